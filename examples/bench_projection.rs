//! Projections per second onto the square-cup die (NUMISHEET'93 dimensions, exact Bezier
//! patches): `cargo run --release --example bench_projection [-- NODES]`.
//!
//! The nodes are a blank's worth of points over the die (plan [-80, 80]^2, up to 1 mm
//! above the flat top, some inside the opening down to the wall): cold start (no hint),
//! warm start (each node moved by up to 0.05 mm from where it was projected, with its
//! previous foot as hint, as between Newton iterations), each with the bounding-volume
//! hierarchy and with a full sort of the patch boxes instead. A wavy quilt of 4096 bilinear
//! patches over the same plan shows the tree's effect with many patches.
use std::time::Instant;
use tribo::geometry::builders::{die_patches, DieSpec, Extent};
use tribo::geometry::{BezierPatch, PatchSurface, RigidSurface, SurfaceHint, Vec3};

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("NODES must be a number"))
        .unwrap_or(100_000);
    let spec = DieSpec::numisheet93();
    let mut seed = 12345u64;
    let mut uniform = |lo: f64, hi: f64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    let nodes: Vec<Vec3> = (0..count)
        .map(|_| {
            let (x, y) = (uniform(-80.0, 80.0), uniform(-80.0, 80.0));
            let z = if x.abs() < 37.0 && y.abs() < 37.0 {
                uniform(-30.0, 1.0)
            } else {
                uniform(0.0, 1.0)
            };
            Vec3::new(x, y, z)
        })
        .collect();
    let moved: Vec<Vec3> = nodes
        .iter()
        .map(|p| p + Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)) * 0.05)
        .collect();
    println!("{count} nodes");
    println!("| tool | patches | search | cold start | warm start |");
    println!("|---|---|---|---|---|");
    // A wavy quilt of 64 x 64 bilinear patches over the same plan: many patches, where the
    // tree has to prune.
    let quilt: Vec<BezierPatch> = {
        let (n, h) = (64, 160.0 / 64.0);
        let z = |i: usize, j: usize| 0.3 * ((i as f64) * 0.7).sin() * ((j as f64) * 0.5).cos();
        let corner =
            |i: usize, j: usize| Vec3::new(-80.0 + i as f64 * h, -80.0 + j as f64 * h, z(i, j));
        (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| {
                let pts = vec![
                    corner(i, j),
                    corner(i, j + 1),
                    corner(i + 1, j),
                    corner(i + 1, j + 1),
                ];
                BezierPatch::new(1, 1, pts, vec![1.0; 4]).unwrap()
            })
            .collect()
    };
    for (name, patches) in [
        ("full die", die_patches(&spec, Extent::Full).unwrap()),
        (
            "quarter die",
            die_patches(&spec, Extent::Quarter { margin: 5.0 }).unwrap(),
        ),
        ("quilt 64 x 64", quilt),
    ] {
        let n_patches = patches.len();
        for bvh in [true, false] {
            let mut surface = PatchSurface::new(patches.clone()).unwrap();
            if !bvh {
                surface = surface.without_bvh();
            }
            let start = Instant::now();
            let hints: Vec<Option<SurfaceHint>> = nodes
                .iter()
                .map(|x| surface.project(x, None).map(|p| p.hint))
                .collect();
            let cold = start.elapsed().as_secs_f64();
            let start = Instant::now();
            let mut checksum = 0.0;
            for (x, h) in moved.iter().zip(&hints) {
                if let Some(p) = surface.project(x, h.as_ref()) {
                    checksum += p.gap;
                }
            }
            let warm = start.elapsed().as_secs_f64();
            assert!(checksum.is_finite());
            println!(
                "| {name} | {n_patches} | {} | {:.0} /s ({:.2} us) | {:.0} /s ({:.2} us) |",
                if bvh { "BVH" } else { "sorted boxes" },
                count as f64 / cold,
                cold / count as f64 * 1e6,
                count as f64 / warm,
                warm / count as f64 * 1e6
            );
        }
    }
}
