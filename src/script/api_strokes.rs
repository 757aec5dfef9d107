//! A production run of several strokes, for scripts (issue 53; the solver's
//! `model::strokes` and `simulation::strokes`):
//!
//! - `sim.strokes(n)`: n strokes of the process, each on a new blank with the tools back at
//!   their start; the tools' fields carry over. `sim.run()` (or `sim.step()` until
//!   `sim.finished()`) runs them all.
//! - `sim.strokes(n, #{ simulate: m })`: simulate the first m strokes and extrapolate the
//!   tools' fields linearly to n (refused when a friction law reads the tool's state).
//! - `sim.strokes(n, #{ update_geometry_every: k })`: after every k strokes the tools'
//!   surfaces are offset along their normals by the wear depth accumulated so far (each
//!   tool with a wear law; `tool::worn`), from stroke k + 1 on. Keys may be combined.
//! - `sim.stroke()`: the stroke the committed state belongs to, from 1.

use super::api_sim::ScriptSim;
use super::convert::*;
use crate::solver::model::strokes::Strokes;
use rhai::{Engine, Map};

pub fn register(engine: &mut Engine) {
    engine.register_fn("strokes", |s: &mut ScriptSim, n: i64| -> ScriptResult<()> {
        set_strokes(s, n, n, None)
    });
    engine.register_fn(
        "strokes",
        |s: &mut ScriptSim, n: i64, options: Map| -> ScriptResult<()> {
            let mut simulate = n;
            let mut every = None;
            for (key, value) in &options {
                match key.as_str() {
                    "simulate" => {
                        simulate = value.as_int().or_else(|_| {
                            runtime_error(format!(
                                "sim.strokes: simulate must be an integer number of strokes, not {value}"
                            ))
                        })?
                    }
                    "update_geometry_every" => {
                        every = Some(value.as_int().or_else(|_| {
                            runtime_error(format!(
                                "sim.strokes: update_geometry_every must be an integer number of strokes, not {value}"
                            ))
                        })?)
                    }
                    other => {
                        return runtime_error(format!(
                            "sim.strokes: unknown option '{other}' (the options are simulate and update_geometry_every)"
                        ))
                    }
                }
            }
            set_strokes(s, n, simulate, every)
        },
    );
    engine.register_fn("stroke", |s: &mut ScriptSim| -> ScriptResult<i64> {
        let mut st = s.borrow_mut();
        Ok(st.simulation()?.stroke() as i64)
    });
}

/// Sets the strokes on the model (before the simulation starts).
fn set_strokes(
    s: &mut ScriptSim,
    n: i64,
    simulate: i64,
    update_geometry_every: Option<i64>,
) -> ScriptResult<()> {
    let mut strokes = lift(Strokes::new(n, simulate))?;
    if let Some(k) = update_geometry_every {
        strokes = lift(strokes.updating_geometry_every(k))?;
    }
    let mut st = s.borrow_mut();
    match st.model_mut() {
        Ok(model) => {
            model.strokes = strokes;
            Ok(())
        }
        Err(_) => runtime_error(
            "sim.strokes must come before the simulation starts (before sim.run(), sim.step(), ...)",
        ),
    }
}
