//! Replays every committed fuzz corpus file and crash reproducer through the check its
//! target runs, so `cargo test` covers them without cargo-fuzz.

use std::path::{Path, PathBuf};

use qem_tests::fuzz_checks::TARGETS;

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz")
}

/// The files of `fuzz/KIND/TARGET`, sorted; none when the directory is absent.
fn files(kind: &str, target: &str) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(fuzz_dir().join(kind).join(target)) else {
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| Some(e.ok()?.path())).collect();
    paths.retain(|p| p.is_file());
    paths.sort();
    paths
}

/// Runs `check` on every file under `fuzz/corpus/TARGET` and `fuzz/regressions/TARGET`,
/// and returns how many seed-corpus files there were. Every failing file is listed.
fn replay(target: &str, check: fn(&[u8])) -> usize {
    let mut failures = Vec::new();
    for kind in ["corpus", "regressions"] {
        for path in files(kind, target) {
            let data = std::fs::read(&path).expect("readable corpus file");
            if std::panic::catch_unwind(|| check(&data)).is_err() {
                failures.push(path.display().to_string());
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{target}: failing files: {failures:#?}"
    );
    files("corpus", target).len()
}

/// One test per target, so a failure names it.
macro_rules! replay_tests {
    ($($name:ident: $target:literal,)*) => {
        $(
            #[test]
            fn $name() {
                let n = replay($target, check_of($target));
                assert!(n > 0, "the {} seed corpus is missing", $target);
            }
        )*

        /// Every target in `TARGETS` has a replay test above (and no other exists).
        #[test]
        fn every_target_is_replayed() {
            let mut listed: Vec<&str> = TARGETS.iter().map(|(name, _)| *name).collect();
            let mut tested = vec![$($target),*];
            listed.sort_unstable();
            tested.sort_unstable();
            assert_eq!(listed, tested);
        }
    };
}

fn check_of(target: &str) -> fn(&[u8]) {
    TARGETS
        .iter()
        .find(|(name, _)| *name == target)
        .map(|(_, check)| *check)
        .expect("a known target")
}

replay_tests! {
    replay_quadric_solve: "quadric_solve",
    replay_simplify_soup: "simplify_soup",
    replay_store_ops: "store_ops",
    replay_grid_pairs: "grid_pairs",
    replay_read_obj: "read_obj",
    replay_read_ply: "read_ply",
    replay_read_stl: "read_stl",
    replay_read_off: "read_off",
    replay_read_gltf: "read_gltf",
}

/// Every directory under `fuzz/corpus` and `fuzz/regressions` belongs to a target, so
/// no reproducer is silently skipped; and every target has a `fuzz_targets/` file.
#[test]
fn every_corpus_directory_has_a_target() {
    for kind in ["corpus", "regressions"] {
        let Ok(entries) = std::fs::read_dir(fuzz_dir().join(kind)) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            assert!(
                TARGETS.iter().any(|(t, _)| *t == name),
                "fuzz/{kind}/{name} has no target"
            );
        }
    }
    for (target, _) in TARGETS {
        let source = fuzz_dir().join("fuzz_targets").join(format!("{target}.rs"));
        assert!(source.is_file(), "{} is missing", source.display());
    }
}

/// The reader seeds with bytes that are not UTF-8 in names and comments (issue 33) must
/// load, not merely fail cleanly: the replay above accepts a one-line error, which is
/// what the readers gave for them before they were lenient.
#[test]
fn seeds_with_non_utf8_names_load() {
    use qem_mesh::io::{read_bytes, Format};
    let seeds = [
        ("read_obj", "latin1_names_bom_crlf", Format::Obj),
        ("read_obj", "non_utf8_unknown_and_nbsp_lines", Format::Obj),
        ("read_ply", "latin1_header_bom_crlf", Format::Ply),
        ("read_off", "latin1_comments_bom_crlf", Format::Off),
        ("read_stl", "latin1_solid_name_bom", Format::Stl),
    ];
    for (target, name, format) in seeds {
        let path = fuzz_dir().join("corpus").join(target).join(name);
        let data = std::fs::read(&path).expect("the seed exists");
        assert!(
            std::str::from_utf8(&data).is_err(),
            "{name} should hold bytes that are not UTF-8"
        );
        let loaded = read_bytes(&data, format)
            .unwrap_or_else(|e| panic!("{}: refused: {e}", path.display()));
        assert!(
            loaded.notes.non_utf8_lines > 0,
            "{name}: {:?}",
            loaded.notes
        );
    }
}
