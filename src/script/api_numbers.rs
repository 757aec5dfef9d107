//! Numbers as people read them: `sig(x)` (6 significant digits) and `sig(x, n)`, so that a
//! script prints `0.3` rather than `0.30000000000000004`. Files keep full precision.

use super::convert::*;
use rhai::Engine;

pub fn register(engine: &mut Engine) {
    engine.register_fn("sig", |x: f64| crate::output::significant(x, 6));
    engine.register_fn("sig", |x: i64| x.to_string());
    engine.register_fn("sig", |x: f64, digits: i64| -> ScriptResult<String> {
        if !(1..=17).contains(&digits) {
            return runtime_error(format!("sig(x, {digits}): digits must be from 1 to 17"));
        }
        Ok(crate::output::significant(x, digits as usize))
    });
}
