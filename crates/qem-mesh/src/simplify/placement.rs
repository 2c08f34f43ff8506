//! Where the merged vertex of a pair goes: a locked end stays put, otherwise the
//! placement rule of the options decides (qem-core's fallback chains).

use super::options::PlacementMode;
use qem_core::{
    endpoint_placement, optimal_placement, solve_first_placement, DVec3, Placement, PlacementRule,
    Quadric,
};

/// Where the merged vertex of a pair goes, given the merged quadric `q` and each end's
/// position and lock: a locked end stays put (the first, if both are), otherwise
/// `placement` decides.
pub(super) fn place_merged(
    q: &Quadric,
    [(pa, locked_a), (pb, locked_b)]: [(DVec3, bool); 2],
    placement: PlacementMode,
) -> Placement {
    let fixed = if locked_a {
        Some((pa, PlacementRule::FirstEnd))
    } else if locked_b {
        Some((pb, PlacementRule::SecondEnd))
    } else {
        None
    };
    if let Some((position, rule)) = fixed {
        let cost = q.evaluate(position).max(0.0);
        return Placement {
            position,
            cost,
            rule,
        };
    }
    match placement {
        PlacementMode::Optimal => optimal_placement(q, pa, pb),
        PlacementMode::EndpointOrMidpoint => endpoint_placement(q, pa, pb),
        PlacementMode::SolveFirst => solve_first_placement(q, pa, pb),
    }
}
