//! `qem simplify` keeps what the mesh carries and says so in its report.
#![allow(clippy::unwrap_used)]

use crate::common::{simplify_spot as run_on_spot, spot, stderr};
use qem_mesh::attributes::ChannelKind;

/// Runs `qem simplify spot.obj -o <name> --ratio 0.1 --report` and returns the
/// written mesh and the report.
fn simplify_spot(name: &str) -> (qem_mesh::IndexedMesh, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join(name);
    let report = dir.path().join("report.json");
    let o = run_on_spot(&out, "0.1", &["--report", report.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    (qem_mesh::io::read_path(&out).unwrap().mesh, json)
}

#[test]
fn spot_keeps_its_uvs_in_obj_and_the_report_says_so() {
    let (mesh, json) = simplify_spot("spot-10.obj");
    assert!(mesh.triangle_count() <= 586); // the count nearest 10% of 5,856
    let uv = mesh
        .attributes
        .channel(ChannelKind::TexCoord)
        .expect("the output has texture coordinates");
    assert!(uv.corners.iter().flatten().all(|&i| i != u32::MAX));
    // Values within the input's range (a best value at a moved vertex interpolates
    // its triangles' fields; it may pass their extremes only by a little).
    let input = qem_mesh::io::read_path(&spot()).unwrap().mesh;
    let input_uv = &input
        .attributes
        .channel(ChannelKind::TexCoord)
        .unwrap()
        .values;
    let lo = input_uv.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = input_uv.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert!(
        uv.values
            .iter()
            .all(|&x| (lo - 0.01..=hi + 0.01).contains(&x)),
        "uvs outside [{lo}, {hi}]"
    );
    assert_eq!(
        json["attributes"]["carried"],
        serde_json::json!(["uv", "materials", "material libraries"])
    );
    assert_eq!(json["attributes"]["dropped"], serde_json::json!([]));
    assert_eq!(
        json["material_files"]["copied"],
        serde_json::json!(["spot.mtl", "spot_checker.png"])
    );
}

/// An OBJ output written to another directory gets its material library and the
/// textures it names beside it; names that leave the directory are not followed, a
/// missing file is reported, and nothing already there is overwritten.
#[test]
fn material_files_follow_the_output_and_only_what_is_safe_is_copied() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in"), dir.path().join("out"));
    std::fs::create_dir_all(input.join("tex")).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    let spot_text = std::fs::read_to_string(spot()).unwrap();
    let text = spot_text.replace("mtllib spot.mtl", "mtllib a.mtl ../outside.mtl missing.mtl");
    assert_ne!(text, spot_text);
    std::fs::write(input.join("m.obj"), text).unwrap();
    std::fs::write(
        input.join("a.mtl"),
        "newmtl spot\nmap_Kd tex/a.png\nbump ../../escape.png\nmap_Ks kept.png\n",
    )
    .unwrap();
    std::fs::write(input.join("tex/a.png"), b"texture").unwrap();
    std::fs::write(input.join("kept.png"), b"new").unwrap();
    std::fs::write(out.join("kept.png"), b"the user's own").unwrap();
    std::fs::write(dir.path().join("outside.mtl"), b"newmtl x\n").unwrap();
    let report = out.join("r.json");
    let o = crate::common::qem(&[
        "simplify",
        crate::common::s(&input.join("m.obj")),
        "-o",
        crate::common::s(&out.join("m.obj")),
        "--ratio",
        "0.5",
        "--report",
        crate::common::s(&report),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let files = &crate::common::json(&report)["material_files"];
    assert_eq!(files["copied"], serde_json::json!(["a.mtl", "tex/a.png"]));
    assert_eq!(std::fs::read(out.join("tex/a.png")).unwrap(), b"texture");
    assert_eq!(
        std::fs::read(out.join("kept.png")).unwrap(),
        b"the user's own"
    );
    let not_copied: Vec<(String, String)> = files["not_copied"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            (
                n["file"].as_str().unwrap().into(),
                n["reason"].as_str().unwrap().into(),
            )
        })
        .collect();
    let reason = |f: &str| {
        not_copied
            .iter()
            .find(|(file, _)| file == f)
            .map(|(_, r)| r.as_str())
            .unwrap_or_else(|| panic!("{f} in {not_copied:?}"))
    };
    assert!(reason("../outside.mtl").contains("leaves the output's directory"));
    assert!(reason("missing.mtl").contains("not found beside the input"));
    assert!(reason("../../escape.png").contains("leaves the output's directory"));
    assert!(reason("kept.png").contains("kept it"));
    assert!(!dir.path().join("escape.png").exists());
    assert!(
        stderr(&o).contains("material files not copied: "),
        "{}",
        stderr(&o)
    );
}

#[test]
fn stl_output_drops_the_uvs_and_the_report_says_why() {
    let (mesh, json) = simplify_spot("spot-10.stl");
    assert!(mesh.attributes.is_empty());
    assert_eq!(json["attributes"]["carried"], serde_json::json!([]));
    assert_eq!(json["attributes"]["dropped"][0]["what"], "uv");
    assert_eq!(
        json["attributes"]["dropped"][0]["reason"],
        "STL holds positions only"
    );
}

#[test]
fn attribute_weights_change_the_result_and_bad_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = |weights: &str, name: &str| {
        let out = dir.path().join(name);
        let o = run_on_spot(&out, "0.1", &["--attribute-weights", weights]);
        (o, out)
    };
    let (o, free) = run("uv=0", "free.obj");
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, heavy) = run("uv=3,normal=1", "heavy.obj");
    assert!(o.status.success(), "{}", stderr(&o));
    let (free, heavy) = (
        qem_mesh::io::read_path(&free).unwrap().mesh,
        qem_mesh::io::read_path(&heavy).unwrap().mesh,
    );
    // Weight 0 still carries the values; the weight changes where vertices go.
    assert!(free.attributes.channel(ChannelKind::TexCoord).is_some());
    assert_ne!(free.positions, heavy.positions);
    let (o, _) = run("uvw=1", "bad.obj");
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("`uvw` is not a channel kind"),
        "{}",
        stderr(&o)
    );
}

/// A link beside the input to a file outside its directory is not copied (a texture
/// that links to a key would otherwise land, as a plain file, beside the output); a
/// link that stays inside is, and an output beside its input copies nothing.
#[cfg(unix)]
#[test]
fn material_files_do_not_follow_links_out_of_the_input_directory() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in"), dir.path().join("out"));
    std::fs::create_dir_all(&input).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    std::fs::copy(spot(), input.join("m.obj")).unwrap();
    std::fs::write(
        input.join("spot.mtl"),
        "newmtl spot\nmap_Kd secret.png\nmap_Ks inside.png\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("secret"), b"a key").unwrap();
    std::os::unix::fs::symlink(dir.path().join("secret"), input.join("secret.png")).unwrap();
    std::fs::write(input.join("real.png"), b"texture").unwrap();
    std::os::unix::fs::symlink(input.join("real.png"), input.join("inside.png")).unwrap();
    let report = out.join("r.json");
    let run = |output: &std::path::Path| {
        crate::common::qem(&[
            "simplify",
            crate::common::s(&input.join("m.obj")),
            "-o",
            crate::common::s(output),
            "--ratio",
            "0.5",
            "--report",
            crate::common::s(&report),
        ])
    };
    let o = run(&out.join("m.obj"));
    assert!(o.status.success(), "{}", stderr(&o));
    let files = &crate::common::json(&report)["material_files"];
    assert_eq!(
        files["copied"],
        serde_json::json!(["spot.mtl", "inside.png"])
    );
    assert_eq!(files["not_copied"][0]["file"], "secret.png");
    assert!(!out.join("secret.png").exists());
    assert_eq!(std::fs::read(out.join("inside.png")).unwrap(), b"texture");
    // Beside its input: nothing to copy.
    let o = run(&input.join("m-10.obj"));
    assert!(o.status.success(), "{}", stderr(&o));
    let files = &crate::common::json(&report)["material_files"];
    assert_eq!(files["copied"], serde_json::json!([]));
    assert_eq!(files["not_copied"], serde_json::json!([]));
}
