//! Issue 53: the frames of a tool worn by a strokes' geometry update
//! (`update_geometry_every`, src/tool/worn.rs) draw the surface the contact sees
//! (src/output/tool_fields.rs): each cell's corners moved by `-h n`, `h` the wear depth
//! applied to the cell. Scene: the roller of tests/strokes.rs (two cylinder patches of
//! radius 5 pressed into an elastic block and dragged along it, tool-side fields on the
//! roller, wearing fast: k / H = 1e-5 /MPa), two strokes of 12 increments; frames written
//! by the run output itself (`RunOutput::write_frame`) and read back from the VTU files.
//!
//! - After the update (one increment into stroke 2), every point of the roller's frame lies
//!   at the applied depth of its quad's cell inside the exact roller: its distance to the
//!   exact surface (closest-point projection, in the roller's frame at its pose) equals
//!   that depth to 1e-10 (the projection converges to round-off of the radius 5; the depths
//!   reach 1e-5 to 1e-2, far above the tolerance; points pass through the file as exact
//!   f64, binary base64).
//! - Without the option, the frame at the same state is the exact roller (every point on
//!   it to 1e-12, grid nodes shared), and with the option the frame written before the
//!   update is byte for byte the run's without it.

mod common;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use tribo::contact::FrictionLaw;
use tribo::geometry::{BezierPatch, PatchSurface, Vec3};
use tribo::output::{read_vtu, OutputOptions, RunOutput};
use tribo::solver::model::strokes::Strokes;
use tribo::solver::{Model, Simulation};
use tribo::tool::{FieldSpec, WearLaw};

/// The wearing roller of tests/strokes.rs with `strokes`.
fn roller(strokes: Strokes) -> Model {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 3.0);
    let axis = Vec3::new(2.0, -0.5, 2.0 + 5.0 + 0.02);
    let patches = (0..2)
        .map(|k| {
            BezierPatch::cylinder_patch(
                axis,
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, -1.0),
                (-60.0 + 60.0 * k as f64).to_radians(),
                60f64.to_radians(),
                5.0,
                2.0,
            )
            .unwrap()
        })
        .collect();
    let contact = &mut model.contacts[0];
    contact.tool.surface = Arc::new(PatchSurface::new(patches).unwrap());
    contact.tool.friction = FrictionLaw::coulomb(0.2).unwrap();
    contact.tool.fields = Some(FieldSpec {
        wear: WearLaw::archard(1.0, 1e5).unwrap(),
        cell: None,
    });
    model.settings.increments = 12;
    model.strokes = strokes;
    model
}

/// Runs stroke 1, writing a frame at its end into `out/before`, then one increment of
/// stroke 2, writing a frame into `out/after`; returns the simulation and the two roller
/// frame files.
fn run(strokes: Strokes, out: &Path) -> (Simulation, PathBuf, PathBuf) {
    let mut sim = Simulation::new(roller(strokes)).unwrap();
    let frame = |sim: &Simulation, name: &str| {
        let dir = out.join(name);
        let mut output = RunOutput::create(&dir, sim, OutputOptions::default_for(3.0)).unwrap();
        output.write_frame(sim).unwrap();
        dir.join("frames/frame_0000_roller.vtu")
    };
    while !(sim.stroke() == 1 && sim.stroke_done()) {
        sim.step().unwrap();
    }
    let before = frame(&sim, "before");
    let r = sim.step().unwrap();
    assert_eq!(r.stroke, 2);
    let after = frame(&sim, "after");
    (sim, before, after)
}

#[test]
fn the_frames_of_a_worn_roller_draw_the_worn_surface() {
    let dir = common::TestDir::new(&format!("tribo-worn-frames-{}", std::process::id()));
    let plain = Strokes::new(2, 2).unwrap();
    let (_, exact_before, exact_after) = run(plain, &dir.join("exact"));
    let (worn, worn_before, worn_after) =
        run(plain.updating_geometry_every(1).unwrap(), &dir.join("worn"));
    assert_eq!(
        std::fs::read(&exact_before).unwrap(),
        std::fs::read(&worn_before).unwrap(),
        "before the update the frames are the same bytes"
    );
    let surface = worn.model.contacts[0].tool.surface.clone();
    let fields = worn.tool_fields(0).unwrap();
    let depth = worn.applied_tool_wear(0).expect("worn after stroke 1");
    let pose = worn.tool_pose(0);
    // Distance of a frame point to the exact roller, positive outside.
    let gap = |x: [f64; 3]| {
        let local = pose.to_local(&Vec3::from(x));
        surface.project(&local, None).unwrap().gap
    };
    let f = read_vtu(&worn_after).unwrap();
    assert_eq!(f.quads.len(), fields.len());
    assert_eq!(
        f.points.len(),
        4 * fields.len(),
        "each cell its own corners"
    );
    let (mut largest, mut checked) = (0.0f64, 0);
    for (c, quad) in f.quads.iter().enumerate() {
        for &p in quad {
            let d = gap(f.points[p]);
            assert!(
                (d + depth[c]).abs() <= 1e-10,
                "cell {c}: distance {d:e} to the exact roller, applied depth {:e}",
                depth[c]
            );
            checked += 1;
        }
        largest = largest.max(depth[c]);
    }
    println!("{checked} frame points checked, largest applied depth {largest:e}");
    assert!(
        largest > 1e-5,
        "the wear is far above the tolerance: {largest:e}"
    );
    // Without the option: the exact roller on shared grid nodes.
    let f = read_vtu(&exact_after).unwrap();
    let nodes: usize = fields.grids.iter().map(|g| (g.nu + 1) * (g.nv + 1)).sum();
    assert_eq!((f.points.len(), f.quads.len()), (nodes, fields.len()));
    for x in &f.points {
        assert!(gap(*x).abs() <= 1e-12, "{x:?}: {:e}", gap(*x));
    }
}
