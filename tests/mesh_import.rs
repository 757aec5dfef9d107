//! Meshes from Gmsh and CalculiX/Abaqus files through the script API: the same mesh as
//! block() with the same sets and results (tests/data/mesh/same_as_block.rhai), errors
//! that name file:line, and reads held to the read policy.

use std::path::PathBuf;
use tribo::script::{self, HostOptions};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mesh")
        .join(name)
}

fn host(tag: &str) -> HostOptions {
    HostOptions {
        out_dir: std::env::temp_dir()
            .join(format!("tribo-mesh-import-{}-{tag}", std::process::id())),
        script_print: true,
        ..HostOptions::default()
    }
}

#[test]
fn gmsh_and_inp_blocks_equal_block() {
    script::run_file(&data("same_as_block.rhai"), &[], &host("same")).unwrap();
}

/// A script in a temporary folder with a deck beside it: the error names the deck's line.
fn run_with(files: &[(&str, &str)], script: &str) -> String {
    let dir = std::env::temp_dir().join(format!(
        "tribo-mesh-import-case-{}-{}",
        std::process::id(),
        files.len() + script.len()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("case.rhai");
    std::fs::write(&path, script).unwrap();
    let out = script::run_file(&path, &[], &host("case"))
        .unwrap_err()
        .to_string();
    std::fs::remove_dir_all(&dir).ok();
    out
}

#[test]
fn errors_name_the_file_and_line() {
    let e = run_with(
        &[
            ("m.inp", "*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=part.inp\n"),
            ("part.inp", "** part\n*ELEMENT, TYPE=C3D10\n"),
        ],
        "let m = mesh_from_inp(\"m.inp\");\n",
    );
    assert!(e.contains("part.inp:2") && e.contains("C3D10"), "{e}");
    assert!(e.contains("m.inp:3"), "the include line is named too: {e}");
    assert!(e.contains("case.rhai:1"), "{e}");

    let e = run_with(&[], "let m = mesh_from_inp(\"../../etc/passwd\");\n");
    assert!(e.contains("outside the folders scripts may read"), "{e}");
    let e = run_with(
        &[("m.inp", "*INCLUDE, INPUT=/etc/hostname\n")],
        "let m = mesh_from_inp(\"m.inp\");\n",
    );
    assert!(
        e.contains("m.inp:1") && e.contains("outside the folders"),
        "{e}"
    );
    let e = run_with(
        &[(
            "x.msh",
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2\n",
        )],
        "let m = mesh_from_gmsh(\"x.msh\");\n",
    );
    assert!(e.contains("x.msh:"), "{e}");
}
