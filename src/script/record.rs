//! A map handed to a script as one opaque value: the entries of `sim.history()` (one
//! increment report each) and of `sim.node_history(name, node)` (one increment of a node).
//!
//! Why: Rhai counts the entries of every map nested in a value against one engine-wide
//! limit (`set_max_map_size`, 65 536 here: the sandbox's bound on what a script builds), so
//! an array of N maps of k entries stops at N k > 65 536 ("Size of object map too large"):
//! `sim.history()`, with 19 entries an increment and two of each tool, at about 3 100
//! increments of a one-tool run. A
//! [`Record`] is a registered type; the size check does not look inside it, so an array of
//! records is bounded only by the array limit (65 536 entries by default, `--max-array-size`). It reads like the map
//! it carries: `r.time` and `r["time"]` (an indexer, which Rhai also uses for property
//! access), `"time" in r`, `r.keys()`; printed as the map; `r.to_map()` gives the map where
//! a script needs one (`sim.summary`, changing it).

use super::convert::*;
use rhai::{Array, Dynamic, Engine, Map};
use std::rc::Rc;

/// A map as one value (see the module docs). Shared, so that copying it (reading it out
/// of an array) copies no entries.
#[derive(Clone, Debug)]
pub struct Record(Rc<Map>);

impl Record {
    pub fn new(map: Map) -> Record {
        Record(Rc::new(map))
    }

    pub fn map(&self) -> &Map {
        &self.0
    }

    /// The entry `key`; an error naming the fields there are.
    fn get(&self, key: &str) -> ScriptResult<Dynamic> {
        match self.0.get(key) {
            Some(v) => Ok(v.clone()),
            None => runtime_error(format!(
                "this record has no field '{key}' (its fields: {})",
                self.0
                    .keys()
                    .map(|k| k.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}

/// Registers the type, its indexer (and so its properties), `keys`, `contains` (`in`),
/// `to_map` and its printed form (that of the map).
pub fn register(engine: &mut Engine) {
    engine.register_type_with_name::<Record>("Record");
    engine.register_indexer_get(|r: &mut Record, key: &str| r.get(key));
    engine.register_fn("keys", |r: &mut Record| -> Array {
        r.0.keys().map(|k| Dynamic::from(k.to_string())).collect()
    });
    engine.register_fn("contains", |r: &mut Record, key: &str| {
        r.0.contains_key(key)
    });
    engine.register_fn("len", |r: &mut Record| r.0.len() as i64);
    engine.register_fn("to_map", |r: &mut Record| (*r.0).clone());
    engine.register_fn("to_string", |r: &mut Record| {
        Dynamic::from((*r.0).clone()).to_string()
    });
    engine.register_fn("to_debug", |r: &mut Record| {
        format!("{:?}", Dynamic::from((*r.0).clone()))
    });
}
