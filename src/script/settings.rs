//! The keys of `sim.settings(#{ ... })`, in one table.
//!
//! Each entry of [`SETTINGS`] is a key, a valid value of it and the function that reads
//! the value into the settings. The parser ([`apply_settings`]) and the list of keys
//! ([`SETTING_KEYS`]: the unknown-key message and the REPL's completion) are both read
//! from it, so they cannot disagree. A new setting is one entry here and its mention in
//! docs/script-api.md; the tests below check that every key is documented and that its
//! example is accepted and changes the settings.

use super::convert::*;
use crate::contact::{Enforcement, FrameUpdate, FrictionUpdate};
use crate::element::{ElementKind, StrainTheory};
use crate::output::formability::{Flc, FormabilityOptions};
use crate::output::{Cadence, Configuration, OutputOptions, Units};
use crate::solver::{AntiCycling, LinearSolverKind, SolverSettings, StepMode};
use crate::Error;
use rhai::{Dynamic, Map};

/// The output settings of a script: `output_every` (0: no output), `output_interval`,
/// `frame_points`, `units`, `model_fraction`. The cadence is resolved when the simulation
/// starts (the default interval depends on the end time).
#[derive(Clone, Debug)]
pub(super) struct FrameKnobs {
    pub(super) off: bool,
    cadence: Option<Cadence>,
    points: Configuration,
    pub(super) units: Units,
    model_fraction: f64,
    /// The forming limit curve and zone thresholds (`flc`, `flc_safety_margin`, ...).
    pub(super) formability: FormabilityOptions,
    /// `trim_tolerance`: chord tolerance of trimmed tools' drawn trims (`None`: relative).
    trim_tolerance: Option<f64>,
}

impl Default for FrameKnobs {
    fn default() -> Self {
        FrameKnobs {
            off: false,
            cadence: None,
            points: Configuration::Current,
            units: Units::default(),
            model_fraction: 1.0,
            formability: FormabilityOptions::default(),
            trim_tolerance: None,
        }
    }
}

impl FrameKnobs {
    pub(super) fn options(&self, end_time: f64) -> OutputOptions {
        OutputOptions {
            points: self.points,
            cadence: self
                .cadence
                .unwrap_or_else(|| Cadence::default_for(end_time)),
            units: self.units.clone(),
            model_fraction: self.model_fraction,
            formability: self.formability.clone(),
            trim_tolerance: self.trim_tolerance,
        }
    }
}

/// What the script layer itself keeps of the settings (the rest is the solver's
/// [`SolverSettings`]).
#[derive(Debug)]
pub(super) struct Knobs {
    pub(super) frames: FrameKnobs,
    pub(super) checkpoint_every: usize,
    /// `--max-increments`: a larger `increments` setting is refused.
    pub(super) max_increments: usize,
    /// Whether the script chose `kinematics` itself (the default "small" is refused past
    /// the small-strain range; a chosen one only warned about).
    pub(super) kinematics_chosen: bool,
}

/// One key of `sim.settings(#{ ... })`.
pub(super) struct Setting {
    pub(super) key: &'static str,
    /// A valid value, written as in a script, that differs from the default (the tests
    /// apply it; docs/script-api.md says what the key means and what it takes).
    #[cfg_attr(not(test), allow(dead_code))]
    example: &'static str,
    /// Reads the value into the settings; its errors name the key.
    apply: Apply,
}

type Apply = fn(&mut SolverSettings, &mut Knobs, Value) -> ScriptResult<()>;

const fn setting(key: &'static str, example: &'static str, apply: Apply) -> Setting {
    Setting {
        key,
        example,
        apply,
    }
}

/// Every setting, in the order the unknown-key message lists them.
pub(super) const SETTINGS: &[Setting] = &[
    // The run: its length, Newton's budget and tolerances.
    setting("increments", "20", |s, k, v| {
        s.increments = increments(v, k.max_increments)?;
        Ok(())
    }),
    setting("end_time", "2.0", |s, _, v| {
        s.end_time = v.number()?;
        Ok(())
    }),
    setting("max_iterations", "40", |s, _, v| {
        s.max_iterations = v.count()?;
        Ok(())
    }),
    setting("max_cutbacks", "8", |s, _, v| {
        s.max_cutbacks = v.count()?;
        Ok(())
    }),
    setting("force_tolerance", "1e-6", |s, _, v| {
        s.force_rel_tol = v.number()?;
        Ok(())
    }),
    setting("force_abs_tolerance", "1e-6", |s, _, v| {
        s.force_abs_tol = v.number()?;
        Ok(())
    }),
    setting("contact_tolerance", "1e-6", |s, _, v| {
        s.contact_tol = v.number()?;
        Ok(())
    }),
    // Output files and checkpoints.
    setting("output_every", "0", |_, k, v| {
        let n = v.count()?;
        k.frames.off = n == 0;
        k.frames.cadence = (n > 0).then_some(Cadence::Increments(n));
        Ok(())
    }),
    setting("output_interval", "0.1", |_, k, v| {
        k.frames.off = false;
        k.frames.cadence = Some(lift(Cadence::interval(v.number()?))?);
        Ok(())
    }),
    setting("frame_points", "\"reference\"", |_, k, v| {
        k.frames.points = v.either(
            ("current", Configuration::Current),
            ("reference", Configuration::Reference),
        )?;
        Ok(())
    }),
    setting("units", "#{ length: \"mm\" }", |_, k, v| {
        units(v.v, &mut k.frames.units)?;
        k.frames.formability.length_unit = k.frames.units.length.clone();
        Ok(())
    }),
    setting("model_fraction", "0.25", |_, k, v| {
        let f = v.number()?;
        if !(f > 0.0 && f <= 1.0) {
            return fail(Error::input(
                v.key,
                f,
                "must be in (0, 1] (1/4 for a quarter model)",
            ));
        }
        k.frames.model_fraction = f;
        Ok(())
    }),
    setting("trim_tolerance", "0.05", |_, k, v| {
        let tol = v.number()?;
        if !(tol > 0.0 && tol.is_finite()) {
            return fail(Error::input(
                v.key,
                tol,
                "must be a positive length (the largest distance of a drawn trim from the exact one)",
            ));
        }
        k.frames.trim_tolerance = Some(tol);
        Ok(())
    }),
    // Formability: the forming limit curve and the zone thresholds.
    setting(
        "flc",
        "[[-0.2, 0.5], [0.0, 0.3], [0.3, 0.45]]",
        |_, k, v| {
            k.frames.formability.flc = Some(flc_table(v)?);
            Ok(())
        },
    ),
    setting("flc_safety_margin", "0.05", |_, k, v| {
        k.frames.formability.thresholds.safety_margin = non_negative(v)?;
        Ok(())
    }),
    setting("thinning_limit", "20.0", |_, k, v| {
        k.frames.formability.thresholds.thinning_limit = non_negative(v)?;
        Ok(())
    }),
    setting("stretch_limit", "0.01", |_, k, v| {
        k.frames.formability.thresholds.stretch_limit = non_negative(v)?;
        Ok(())
    }),
    setting("wrinkle_limit", "0.03", |_, k, v| {
        k.frames.formability.thresholds.wrinkle_limit = non_negative(v)?;
        Ok(())
    }),
    setting("checkpoint_every", "5", |_, k, v| {
        k.checkpoint_every = v.count()?;
        Ok(())
    }),
    // Contact.
    setting("curvature", "false", |s, _, v| {
        s.contact.curvature = v.flag()?;
        Ok(())
    }),
    setting("frame", "\"frozen\"", |s, _, v| {
        s.contact.frame = v.either(
            ("every_iteration", FrameUpdate::EveryIteration),
            ("frozen", FrameUpdate::Frozen),
        )?;
        Ok(())
    }),
    setting("enforcement", "\"penalty\"", |s, _, v| {
        s.contact.enforcement = v.either(
            ("augmented_lagrangian", Enforcement::AugmentedLagrangian),
            ("penalty", Enforcement::Penalty),
        )?;
        Ok(())
    }),
    setting("r_fraction", "0.5", |s, _, v| {
        let f = v.number()?;
        if !(f > 0.0 && f.is_finite()) {
            return fail(Error::input(v.key, f, "must be > 0"));
        }
        s.contact.r_fraction = f;
        Ok(())
    }),
    setting("friction_update", "\"implicit\"", |s, _, v| {
        s.contact.friction_update = v.either(
            ("explicit", FrictionUpdate::Explicit),
            ("implicit", FrictionUpdate::Implicit),
        )?;
        Ok(())
    }),
    // The linear solve and the Newton iteration.
    setting("eliminate_multipliers", "false", |s, _, v| {
        s.eliminate_multipliers = v.flag()?;
        Ok(())
    }),
    setting("linear_solver", "\"lu\"", |s, _, v| {
        s.linear_solver = LinearSolverKind::from_name(&v.text()).or_else(runtime_error)?;
        Ok(())
    }),
    setting("extrapolate", "false", |s, _, v| {
        s.extrapolate = v.flag()?;
        Ok(())
    }),
    setting("status_prediction", "0", |s, _, v| {
        s.status_prediction = v.count()?;
        Ok(())
    }),
    setting("threads", "2", |s, _, v| {
        s.threads = v.count()?;
        Ok(())
    }),
    // Elements.
    setting("kinematics", "\"finite\"", |s, k, v| {
        s.kinematics = lift(StrainTheory::from_name(&v.text()))?;
        k.kinematics_chosen = true;
        Ok(())
    }),
    setting("fbar", "false", |s, _, v| {
        s.fbar = v.flag()?;
        Ok(())
    }),
    setting("element", "\"solid_shell\"", |s, _, v| {
        s.element = lift(ElementKind::from_name(&v.text()))?;
        Ok(())
    }),
    setting("thickness_points", "3", |s, _, v| {
        s.thickness_points = lift(crate::element::solid_shell::check_thickness_points(
            v.count()?,
        ))?;
        Ok(())
    }),
    // Stepping: step control, line search, anti-cycling, rollback, last resorts.
    setting("step_control", "\"adaptive\"", |s, _, v| {
        s.stepping.mode =
            v.one_of(&[("fixed", StepMode::Fixed), ("adaptive", StepMode::Adaptive)])?;
        Ok(())
    }),
    setting("dt_min", "1e-3", |s, _, v| {
        s.stepping.dt_min = Some(v.number()?);
        Ok(())
    }),
    setting("dt_max", "0.5", |s, _, v| {
        s.stepping.dt_max = Some(v.number()?);
        Ok(())
    }),
    setting("dt_initial", "0.01", |s, _, v| {
        s.stepping.dt_initial = Some(v.number()?);
        Ok(())
    }),
    setting("max_plastic_strain_increment", "0.02", |s, _, v| {
        s.stepping.max_plastic_strain_increment = v.number()?;
        Ok(())
    }),
    setting("max_rotation_increment", "0.05", |s, _, v| {
        s.stepping.max_rotation_increment = v.number()?;
        Ok(())
    }),
    setting("max_slip_increment", "0.2", |s, _, v| {
        s.stepping.max_slip_increment = v.number()?;
        Ok(())
    }),
    setting("target_iterations", "8", |s, _, v| {
        s.stepping.target_iterations = v.count()?;
        Ok(())
    }),
    setting("step_growth", "1.5", |s, _, v| {
        s.stepping.growth = v.number()?;
        Ok(())
    }),
    setting("line_search", "false", |s, _, v| {
        s.stepping.line_search = v.flag()?;
        Ok(())
    }),
    setting("anti_cycling", "\"freeze\"", |s, _, v| {
        s.stepping.anti_cycling = v.one_of(&[
            ("freeze", AntiCycling::Freeze),
            ("damp", AntiCycling::Damp),
            ("off", AntiCycling::Off),
        ])?;
        Ok(())
    }),
    setting("cycle_flips", "4", |s, _, v| {
        s.stepping.cycle_flips = v.count()?;
        Ok(())
    }),
    setting("rollback_depth", "5", |s, _, v| {
        s.stepping.rollback_depth = v.count()?;
        Ok(())
    }),
    setting("last_resort", "false", |s, _, v| {
        s.stepping.last_resort = v.flag()?;
        Ok(())
    }),
];

/// Every key `sim.settings(#{ ... })` accepts, in [`SETTINGS`]' order (its error message
/// and the REPL's completion list them from here).
pub const SETTING_KEYS: &[&str] = &keys::<{ SETTINGS.len() }>();

const fn keys<const N: usize>() -> [&'static str; N] {
    let mut out = [""; N];
    let mut i = 0;
    while i < N {
        out[i] = SETTINGS[i].key;
        i += 1;
    }
    out
}

/// Applies `spec` key by key, in the map's (sorted) order, then checks what the keys
/// bound together (positive run length and tolerances, the step sizes against the end
/// time). An unknown key or a bad value stops at it: the keys before it stay applied.
pub(super) fn apply_settings(
    s: &mut SolverSettings,
    knobs: &mut Knobs,
    spec: &Map,
) -> ScriptResult<()> {
    for (key, v) in spec {
        let Some(setting) = SETTINGS.iter().find(|x| x.key == key.as_str()) else {
            return runtime_error(format!(
                "unknown setting '{key}' (known: {})",
                SETTING_KEYS.join(", ")
            ));
        };
        (setting.apply)(
            s,
            knobs,
            Value {
                key: setting.key,
                v,
            },
        )?;
    }
    for (what, v) in [
        ("increments", s.increments as f64),
        ("end_time", s.end_time),
        ("max_iterations", s.max_iterations as f64),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return fail(Error::input(what, v, "must be > 0"));
        }
    }
    for (what, v) in [
        ("force_tolerance", s.force_rel_tol),
        ("contact_tolerance", s.contact_tol),
    ] {
        if v.is_nan() || v <= 0.0 {
            return fail(Error::input(what, v, "must be > 0"));
        }
    }
    lift(s.stepping.validate(s.end_time))
}

/// A setting's value with its key, read as the key needs it; every error names the key.
#[derive(Clone, Copy)]
struct Value<'a> {
    key: &'static str,
    v: &'a Dynamic,
}

impl Value<'_> {
    /// An integer or a float.
    fn number(self) -> ScriptResult<f64> {
        number(self.v, self.key)
    }

    /// A whole number >= 0 (below 10^12).
    fn count(self) -> ScriptResult<usize> {
        let x = self.number()?;
        if x >= 0.0 && x.fract() == 0.0 && x < 1e12 {
            Ok(x as usize)
        } else {
            fail(Error::input(self.key, x, "must be a whole number >= 0"))
        }
    }

    fn flag(self) -> ScriptResult<bool> {
        self.v
            .as_bool()
            .map_err(|t| format!("{} must be true or false, got {t}", self.key))
            .or_else(runtime_error)
    }

    /// The text of a string ("" for any other value).
    fn text(self) -> String {
        self.v.clone().into_string().unwrap_or_default()
    }

    /// The value named by a string, one of two (`key = 'x' must be "a" or "b"`).
    fn either<T>(self, a: (&str, T), b: (&str, T)) -> ScriptResult<T> {
        let text = self.text();
        if text == a.0 {
            Ok(a.1)
        } else if text == b.0 {
            Ok(b.1)
        } else {
            runtime_error(format!(
                "{} = '{text}' must be \"{}\" or \"{}\"",
                self.key, a.0, b.0
            ))
        }
    }

    /// The value named by a string among `options` (`key = 'x' must be one of "a", "b",
    /// "c"`; a value that is no string is named by its type).
    fn one_of<T: Copy>(self, options: &[(&str, T)]) -> ScriptResult<T> {
        let text = self
            .v
            .clone()
            .into_string()
            .unwrap_or_else(|t| format!("({t})"));
        match options.iter().find(|(name, _)| *name == text) {
            Some((_, value)) => Ok(*value),
            None => runtime_error(format!(
                "{} = '{text}' must be one of {}",
                self.key,
                options
                    .iter()
                    .map(|(name, _)| format!("\"{name}\""))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}

/// A finite number >= 0.
fn non_negative(v: Value) -> ScriptResult<f64> {
    let x = v.number()?;
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        fail(Error::input(v.key, x, "must be finite and >= 0"))
    }
}

/// `flc: [[minor, major], ...]`, true strains, minor strictly increasing.
fn flc_table(v: Value) -> ScriptResult<Flc> {
    let Some(rows) = v.v.clone().try_cast::<rhai::Array>() else {
        return runtime_error(format!(
            "{} must be an array of [minor, major] pairs, got {}",
            v.key,
            v.v.type_name()
        ));
    };
    let mut points = Vec::with_capacity(rows.len());
    for (i, row) in rows.iter().enumerate() {
        let pair = row
            .clone()
            .try_cast::<rhai::Array>()
            .filter(|r| r.len() == 2);
        let Some(pair) = pair else {
            return runtime_error(format!("{} point {i} must be a [minor, major] pair", v.key));
        };
        let at = format!("{} point {i}", v.key);
        points.push([number(&pair[0], &at)?, number(&pair[1], &at)?]);
    }
    lift(Flc::table(points))
}

/// `increments`: a whole number from 1 to the `--max-increments` cap.
fn increments(v: Value, cap: usize) -> ScriptResult<usize> {
    let n = v.number()?;
    if !(n >= 1.0 && n <= cap as f64 && n.fract() == 0.0) {
        return fail(Error::input(
            v.key,
            n,
            &format!(
                "must be a whole number from 1 to {cap} (raise the cap with --max-increments)"
            ),
        ));
    }
    Ok(n as usize)
}

/// `units: #{ length: "mm", force: "N", time: "mm" }` (each key optional).
fn units(v: &Dynamic, into: &mut Units) -> ScriptResult<()> {
    let Some(map) = v.clone().try_cast::<Map>() else {
        return runtime_error(format!(
            "units must be a map #{{ length: \"mm\", force: \"N\", time: \"s\" }}, got {}",
            v.type_name()
        ));
    };
    for (key, value) in &map {
        let Ok(name) = value.clone().into_string() else {
            return runtime_error(format!("units.{key} must be a string"));
        };
        if name.contains([',', '"', '[', ']', '\n', '\r']) {
            return runtime_error(format!(
                "units.{key} = '{name}' must not contain , \" [ ] or line breaks (it names CSV columns)"
            ));
        }
        match key.as_str() {
            "length" => into.length = name,
            "force" => into.force = name,
            "time" => into.time = name,
            other => {
                return runtime_error(format!(
                    "unknown unit '{other}' (known: length, force, time)"
                ))
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn knobs() -> Knobs {
        Knobs {
            frames: FrameKnobs::default(),
            checkpoint_every: 0,
            max_increments: usize::MAX,
            kinematics_chosen: false,
        }
    }

    /// The settings and the script layer's knobs after `spec`, or the error.
    fn apply(spec: &Map) -> Result<String, String> {
        let (mut s, mut k) = (SolverSettings::default(), knobs());
        apply_settings(&mut s, &mut k, spec).map_err(|e| e.to_string())?;
        Ok(format!("{s:?} {k:?}"))
    }

    fn one(key: &str, value: Dynamic) -> Map {
        let mut spec = Map::new();
        spec.insert(key.into(), value);
        spec
    }

    #[test]
    fn the_key_list_is_the_table() {
        assert_eq!(SETTING_KEYS.len(), SETTINGS.len());
        for (i, (key, setting)) in SETTING_KEYS.iter().zip(SETTINGS).enumerate() {
            assert_eq!(*key, setting.key);
            assert!(!SETTING_KEYS[..i].contains(key), "'{key}' twice");
        }
        let e = apply(&one("no_such_key", Dynamic::UNIT)).unwrap_err();
        let known = format!("(known: {})", SETTING_KEYS.join(", "));
        assert!(
            e.contains(&format!("unknown setting 'no_such_key' {known}")),
            "{e}"
        );
    }

    /// Every key's example is accepted on its own and changes the settings (so each entry
    /// sets what it says), and a unit value is refused by the key's own check.
    #[test]
    fn every_key_reads_its_example_and_refuses_a_unit() {
        let default = apply(&Map::new()).unwrap();
        let engine = rhai::Engine::new();
        for setting in SETTINGS {
            let key = setting.key;
            let value: Dynamic = engine
                .eval_expression(setting.example)
                .unwrap_or_else(|e| panic!("{key}: example {}: {e}", setting.example));
            let changed = apply(&one(key, value))
                .unwrap_or_else(|e| panic!("{key}: {}: {e}", setting.example));
            assert_ne!(
                changed, default,
                "{key}: {} changes nothing",
                setting.example
            );
            let e = apply(&one(key, Dynamic::UNIT)).unwrap_err();
            assert!(
                e.contains(key) && !e.contains("unknown setting"),
                "{key}: {e}"
            );
        }
    }

    /// Every key is described in the script API reference (as `key` or `key: ...`).
    #[test]
    fn every_key_is_in_the_reference() {
        let reference = include_str!("../../docs/script-api.md");
        for key in SETTING_KEYS {
            assert!(
                reference.contains(&format!("`{key}`")) || reference.contains(&format!("`{key}:")),
                "setting '{key}' is not in docs/script-api.md"
            );
        }
    }
}
