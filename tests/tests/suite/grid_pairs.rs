//! The virtual-pair grid against the brute-force reference of
//! [`qem_tests::pair_model`], over random points.

use proptest::prelude::*;
use qem_mesh::pairs::{virtual_pairs, GridOptions};
use qem_tests::pair_model::brute_force_pairs;

fn grid_points() -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec(prop::array::uniform3(0..5i32), 0..40)
        .prop_map(|v| v.into_iter().map(|p| p.map(f64::from)).collect())
}

fn float_points() -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec(prop::array::uniform3(-2.0..2.0f64), 0..60)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn grid_equals_brute_force_on_integer_points(p in grid_points(), t in 0usize..6, k in 1usize..5) {
        // Integer points and integer t: many pairs at exactly distance t (excluded).
        let t = t as f64;
        let all = |_: u32, _: u32| true;
        prop_assert_eq!(virtual_pairs(&p, &GridOptions::new(t), all), brute_force_pairs(&p, t, usize::MAX, all));
        prop_assert_eq!(
            virtual_pairs(&p, &GridOptions::new(t).with_max_per_vertex(k), all),
            brute_force_pairs(&p, t, k, all)
        );
    }

    #[test]
    fn grid_equals_brute_force_on_float_points(p in float_points(), t in 0.01..3.0f64, k in 1usize..4) {
        let odd = |i: u32, j: u32| (i + j) % 3 != 0;
        prop_assert_eq!(virtual_pairs(&p, &GridOptions::new(t), odd), brute_force_pairs(&p, t, usize::MAX, odd));
        prop_assert_eq!(
            virtual_pairs(&p, &GridOptions::new(t).with_max_per_vertex(k), odd),
            brute_force_pairs(&p, t, k, odd)
        );
    }
}
