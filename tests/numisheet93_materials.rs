//! The NUMISHEET'93 sheets of the std-lib (`std-lib/numisheet93.rhai`) against the
//! benchmark's specification: the numbers the module holds are the specified ones, and a
//! homogeneous uniaxial tension test of the mild steel at 0, 45 and 90 degrees to the
//! rolling direction gives back the specified Lankford coefficients and the yield stresses
//! of Hill's 1948 function with the specified Swift curve.
//!
//! Mathematics. Uniaxial stress `σ` along the unit vector at `θ` to the rolling direction
//! x: `σ = σ q`, `q = [c², s², 0, cs, 0, 0]`. Hill48 normalised to the rolling direction,
//! `φ² = F(σyy−σzz)² + G(σzz−σxx)² + H(σxx−σyy)² + 2Nσxy²`, with the Lankford relations
//! `G = 1/(1+r0)`, `H = r0/(1+r0)`, `F = r0/(r90 (1+r0))`,
//! `N = (r0+r90)(1+2 r45)/(2 r90 (1+r0))`, gives `φ = σ √k(θ)`,
//! `k = F s⁴ + G c⁴ + H (c²−s²)² + 2N c²s²`; on the yield surface `φ = σy(ε̄p)`, so the
//! uniaxial yield stress at θ is `σy(ε̄p)/√k(θ)` (Swift `σy = C (ε0 + ε̄p)^n`). The plastic
//! flow `dεp ∝ ∂φ/∂σ` is fixed under uniaxial stress, so the ratio of the width to the
//! thickness plastic strain increments is exactly `r(θ)`. Both hold to round-off at every
//! converged plastic state, hence the 1e-6 relative tolerance (the driver converges the
//! stress to 1e-10 relative).

use rhai::{Dynamic, Map};
use tribo::material::{
    uniaxial_direction, uniaxial_stress_path, ElastoPlastic, Hardening, Hill48, LinearElastic,
    PointState,
};
use tribo::script::{engine, HostOptions};

/// The benchmark's mild steel as specified (NUMISHEET'93, benchmark A; docs/validation):
/// E, nu, Swift C, eps0, n, r0, r45, r90, thickness.
const STEEL: [(&str, f64); 9] = [
    ("young", 206000.0),
    ("poisson", 0.3),
    ("swift_c", 565.32),
    ("swift_eps0", 0.007117),
    ("swift_n", 0.2589),
    ("r0", 1.79),
    ("r45", 1.51),
    ("r90", 2.27),
    ("thickness", 0.78),
];

/// The benchmark's aluminium as specified (the constants verbatim, "aluminium_1993").
const ALUMINIUM: [(&str, f64); 9] = [
    ("young", 71000.0),
    ("poisson", 0.33),
    ("swift_c", 576.79),
    ("swift_eps0", 0.01658),
    ("swift_n", 0.3593),
    ("r0", 0.71),
    ("r45", 0.58),
    ("r90", 0.70),
    ("thickness", 0.81),
];

/// Evaluates `expr` after `import "numisheet93" as cup;` in a scripting engine.
fn eval(expr: &str) -> Result<Dynamic, String> {
    let engine = engine(&HostOptions::default(), None);
    engine
        .eval::<Dynamic>(&format!("import \"numisheet93\" as cup; {expr}"))
        .map_err(|e| e.to_string())
}

fn sheet(name: &str) -> Map {
    eval(&format!("cup::sheet(\"{name}\")"))
        .unwrap()
        .try_cast::<Map>()
        .expect("cup::sheet returns a map")
}

fn get(m: &Map, key: &str) -> f64 {
    m.get(key)
        .and_then(|v| v.as_float().ok())
        .unwrap_or_else(|| panic!("sheet entry {key} missing or not a number"))
}

#[test]
fn the_std_lib_sheets_hold_the_specified_numbers() {
    for (name, spec) in [("steel", STEEL), ("aluminium_1993", ALUMINIUM)] {
        let m = sheet(name);
        for (key, value) in spec {
            assert_eq!(get(&m, key), value, "{name}: {key}");
        }
    }
    // The friction coefficients chosen (docs/validation/numisheet93.md, "Data").
    assert_eq!(get(&sheet("steel"), "mu"), 0.144);
    assert_eq!(get(&sheet("aluminium_1993"), "mu"), 0.162);
    // Both build a material with either yield function; a wrong name is refused by name.
    for kind in ["hill48", "isotropic"] {
        let m = eval(&format!("cup::material(\"steel\", \"{kind}\")")).unwrap();
        assert!(m.type_name().contains("Material"), "{}", m.type_name());
    }
    let err = eval("cup::material(\"brass\", \"hill48\")").unwrap_err();
    assert!(err.contains("brass") && err.contains("steel"), "{err}");
}

/// The steel built from the module's numbers, rolling direction at `angle` to x.
fn steel(angle: f64) -> ElastoPlastic {
    let m = sheet("steel");
    ElastoPlastic::new(
        LinearElastic::new(get(&m, "young"), get(&m, "poisson")).unwrap(),
        Hill48::from_lankford(get(&m, "r0"), get(&m, "r45"), get(&m, "r90"))
            .unwrap()
            .with_rolling_angle(angle)
            .unwrap(),
        Hardening::swift(
            get(&m, "swift_c"),
            get(&m, "swift_eps0"),
            get(&m, "swift_n"),
        )
        .unwrap(),
    )
}

/// Uniaxial stress along x, driven by `εxx` in `steps` equal increments to `eps_max`: per
/// step Newton with the material's consistent tangent solves `σ(ε) = s e_x`, `εxx = target`
/// for `(ε, s)`, every other stress component zero. The committed state after every step.
fn uniaxial_x(m: &ElastoPlastic, eps_max: f64, steps: usize) -> Vec<PointState> {
    let targets: Vec<f64> = (1..=steps)
        .map(|k| eps_max * k as f64 / steps as f64)
        .collect();
    uniaxial_stress_path(m, uniaxial_direction(0.0), &targets).unwrap()
}

#[test]
fn steel_tension_at_0_45_90_degrees_gives_the_specified_r_values_and_yield_stresses() {
    let spec = |key: &str| STEEL.iter().find(|(k, _)| *k == key).unwrap().1;
    let (r0, r45, r90) = (spec("r0"), spec("r45"), spec("r90"));
    let (c, eps0, n) = (spec("swift_c"), spec("swift_eps0"), spec("swift_n"));
    let (g, h) = (1.0 / (1.0 + r0), r0 / (1.0 + r0));
    let f = r0 / (r90 * (1.0 + r0));
    let nn = (r0 + r90) * (1.0 + 2.0 * r45) / (2.0 * r90 * (1.0 + r0));
    for (deg, r_spec) in [(0.0f64, r0), (45.0, r45), (90.0, r90)] {
        // Pulling along x with the rolling direction at -deg is tension at deg to it.
        let theta = deg.to_radians();
        let m = steel(-theta);
        let states = uniaxial_x(&m, 0.05, 25);
        let (s, co) = theta.sin_cos();
        let k = f * s.powi(4)
            + g * co.powi(4)
            + h * (co * co - s * s).powi(2)
            + 2.0 * nn * co * co * s * s;
        let mut plastic = 0;
        for (a, b) in states.iter().zip(&states[1..]) {
            if a.eq_plastic_strain <= 0.0 {
                continue;
            }
            plastic += 1;
            let sigma_y = c * (eps0 + b.eq_plastic_strain).powf(n) / k.sqrt();
            let sigma = b.stress[0];
            assert!(
                (sigma - sigma_y).abs() <= 1e-6 * sigma_y,
                "{deg} deg: stress {sigma} vs yield stress {sigma_y}"
            );
            let dep = b.plastic_strain - a.plastic_strain;
            let r = dep[1] / dep[2];
            assert!(
                (r - r_spec).abs() <= 1e-6 * r_spec,
                "{deg} deg: r = {r}, specified {r_spec}"
            );
        }
        assert!(plastic >= 20, "{deg} deg: only {plastic} plastic steps");
        // The initial yield stress at 0 degrees is the Swift curve's C eps0^n itself.
        if deg == 0.0 {
            assert!((k - 1.0).abs() < 1e-15);
        }
    }
}
