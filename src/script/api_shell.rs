//! Script functions for shell models: `sim.end_moment(set, direction, moment)` and
//! `sim.end_moment(set, direction, moment, scale)`, a follower bending moment on an end
//! face ([`crate::solver::Model::add_end_moment`], `src/solver/model/follower_load.rs`).
//!
//! The traction on the faces of `set` is `p = M y / I` along their current normal, with
//! `y` the reference coordinate along `direction` (the thickness direction) from the faces'
//! centroid and `I = ∫ y² dA`: a pure moment `M` about `direction × n` (`n` the outward
//! normal), which turns with the face. `scale` is a number or a `[[t, s], ...]` table, as
//! for `sim.load`; without it the moment is constant.

use rhai::{Array, Dynamic, Engine};

use super::api_scene::scalar_schedule;
use super::api_sim::ScriptSim;
use super::convert::{lift, number, vec3, ScriptResult};
use crate::tool::schedule::ScalarSchedule;

fn end_moment(
    s: &mut ScriptSim,
    set: &str,
    direction: &Array,
    moment: &Dynamic,
    scale: ScalarSchedule,
) -> ScriptResult<()> {
    let d = vec3(direction, "end_moment direction")?;
    let m = number(moment, "end_moment moment")?;
    lift(s.borrow_mut().model_mut()?.add_end_moment(set, m, d, scale))
}

pub fn register(engine: &mut Engine) {
    engine.register_fn(
        "end_moment",
        |s: &mut ScriptSim, set: &str, direction: Array, moment: Dynamic| -> ScriptResult<()> {
            end_moment(s, set, &direction, &moment, ScalarSchedule::constant(1.0))
        },
    );
    engine.register_fn(
        "end_moment",
        |s: &mut ScriptSim,
         set: &str,
         direction: Array,
         moment: Dynamic,
         scale: Dynamic|
         -> ScriptResult<()> {
            let scale = scalar_schedule(&scale)?;
            end_moment(s, set, &direction, &moment, scale)
        },
    );
}
