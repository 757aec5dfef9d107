//! A production run of several strokes, for scripts (issue 53; the solver's
//! `model::strokes` and `simulation::strokes`):
//!
//! - `sim.strokes(n)`: n strokes of the process, each on a new blank with the tools back at
//!   their start; the tools' fields carry over. `sim.run()` (or `sim.step()` until
//!   `sim.finished()`) runs them all.
//! - `sim.strokes(n, #{ simulate: m })`: simulate the first m strokes and extrapolate the
//!   tools' fields linearly to n (refused when a friction law reads the tool's state).
//! - `sim.stroke()`: the stroke the committed state belongs to, from 1.

use super::api_sim::ScriptSim;
use super::convert::*;
use crate::solver::model::strokes::Strokes;
use rhai::{Engine, Map};

pub fn register(engine: &mut Engine) {
    engine.register_fn("strokes", |s: &mut ScriptSim, n: i64| -> ScriptResult<()> {
        set_strokes(s, n, n)
    });
    engine.register_fn(
        "strokes",
        |s: &mut ScriptSim, n: i64, options: Map| -> ScriptResult<()> {
            let mut simulate = n;
            for (key, value) in &options {
                match key.as_str() {
                    "simulate" => {
                        simulate = value.as_int().or_else(|_| {
                            runtime_error(format!(
                                "sim.strokes: simulate must be an integer number of strokes, not {value}"
                            ))
                        })?
                    }
                    other => {
                        return runtime_error(format!(
                            "sim.strokes: unknown option '{other}' (the only one is simulate)"
                        ))
                    }
                }
            }
            set_strokes(s, n, simulate)
        },
    );
    engine.register_fn("stroke", |s: &mut ScriptSim| -> ScriptResult<i64> {
        let mut st = s.borrow_mut();
        Ok(st.simulation()?.stroke() as i64)
    });
}

/// Sets the strokes on the model (before the simulation starts).
fn set_strokes(s: &mut ScriptSim, n: i64, simulate: i64) -> ScriptResult<()> {
    let strokes = lift(Strokes::new(n, simulate))?;
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
