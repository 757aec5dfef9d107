//! `sim.contact_nodes(name)`, `sim.contact_node(name, node)` and `sim.node_history(name,
//! node)`: a tool's candidate nodes now, one of them, and one's work, mu and status over
//! the converged increments.
//!
//! Per node, the state of the contact law at the node's current position
//! x = X + u: gap g_N, normal multiplier lambda_N (negative in compression), tangential
//! multiplier norm |lambda_T|, tributary area A, pressure p = -lambda_N / A, frictional
//! work, accumulated slip and the friction coefficient mu.
//!
//! Why a record type and not a map per node: Rhai counts the entries of every map nested in
//! a value against one engine-wide limit (`set_max_map_size`, the sandbox's bound on what a
//! script builds), so an array of 11-entry maps stopped at about 6 000 candidate nodes
//! ("Size of object map too large"). A [`ContactNode`] is a registered type with one getter
//! per field: it reads like the map it replaces (`n.work`, `n.x[0]`) and counts as one
//! array entry, so a query returns up to the array limit (65 536 by default) of them, and the
//! engine's limits stay as they are. `n.to_map()` gives the map when a script needs one
//! (keys, `sim.summary`).

use super::api_sim::ScriptSim;
use super::convert::*;
use rhai::{Array, Dynamic, Engine, Map};

/// The status names by [`crate::contact::ContactStatus::code`].
const STATUS: [&str; 3] = ["gap", "stick", "slip"];

/// One candidate node of a tool, as `sim.contact_nodes` returns it.
#[derive(Clone, Debug)]
pub struct ContactNode {
    node: i64,
    x: [f64; 3],
    status: &'static str,
    gap: f64,
    lambda_n: f64,
    lambda_t: f64,
    area: f64,
    pressure: f64,
    work: f64,
    slip: f64,
    mu: f64,
}

impl ContactNode {
    /// The fields in the order the documentation lists them.
    fn fields(&self) -> [(&'static str, Dynamic); 11] {
        let x: Array = self.x.iter().map(|v| Dynamic::from(*v)).collect();
        [
            ("node", Dynamic::from(self.node)),
            ("x", Dynamic::from(x)),
            ("status", Dynamic::from(self.status.to_string())),
            ("gap", Dynamic::from(self.gap)),
            ("lambda_n", Dynamic::from(self.lambda_n)),
            ("lambda_t", Dynamic::from(self.lambda_t)),
            ("area", Dynamic::from(self.area)),
            ("pressure", Dynamic::from(self.pressure)),
            ("work", Dynamic::from(self.work)),
            ("slip", Dynamic::from(self.slip)),
            ("mu", Dynamic::from(self.mu)),
        ]
    }

    pub fn to_map(&self) -> Map {
        self.fields()
            .into_iter()
            .map(|(k, v)| (k.into(), v))
            .collect()
    }
}

/// Registers the queries and the `ContactNode` type with its getters.
pub fn register(engine: &mut Engine) {
    register_record(engine);
    engine.register_fn("contact_nodes", contact_nodes);
    // The state of one mesh node against a tool (a map with the fields of a ContactNode).
    engine.register_fn(
        "contact_node",
        |s: &mut ScriptSim, name: &str, node: i64| -> ScriptResult<Map> {
            candidates(s, name)?
                .into_iter()
                .find(|n| n.node == node)
                .map(|n| n.to_map())
                .ok_or_else(|| format!("node {node} is not a contact candidate of tool '{name}'"))
                .or_else(runtime_error)
        },
    );
    engine.register_fn("node_history", node_history);
}

/// The type's name, getters, `to_map()` and its printed form (that of the map).
fn register_record(engine: &mut Engine) {
    engine.register_type_with_name::<ContactNode>("ContactNode");
    engine.register_get("node", |n: &mut ContactNode| n.node);
    engine.register_get("x", |n: &mut ContactNode| -> Array {
        n.x.iter().map(|v| Dynamic::from(*v)).collect()
    });
    engine.register_get("status", |n: &mut ContactNode| n.status.to_string());
    engine.register_get("gap", |n: &mut ContactNode| n.gap);
    engine.register_get("lambda_n", |n: &mut ContactNode| n.lambda_n);
    engine.register_get("lambda_t", |n: &mut ContactNode| n.lambda_t);
    engine.register_get("area", |n: &mut ContactNode| n.area);
    engine.register_get("pressure", |n: &mut ContactNode| n.pressure);
    engine.register_get("work", |n: &mut ContactNode| n.work);
    engine.register_get("slip", |n: &mut ContactNode| n.slip);
    engine.register_get("mu", |n: &mut ContactNode| n.mu);
    engine.register_fn("to_map", |n: &mut ContactNode| n.to_map());
    engine.register_fn("to_string", |n: &mut ContactNode| {
        Dynamic::from(n.to_map()).to_string()
    });
    engine.register_fn("to_debug", |n: &mut ContactNode| {
        format!("{:?}", Dynamic::from(n.to_map()))
    });
}

/// Every candidate node of the tool `name`, in the order of the tool's candidates.
fn candidates(s: &mut ScriptSim, name: &str) -> ScriptResult<Vec<ContactNode>> {
    let mut st = s.borrow_mut();
    let sim = st.simulation()?;
    let c = lift(sim.model.tool_index(name))?;
    let contact = &sim.model.contacts[c];
    Ok(sim
        .contact_states(c)
        .iter()
        .enumerate()
        .map(|(k, state)| {
            let node = contact.candidates[k];
            let x = sim.model.mesh.nodes[node] + sim.displacement(node);
            let area = contact.areas[k];
            ContactNode {
                node: node as i64,
                x: [x.x, x.y, x.z],
                status: STATUS[state.status.code() as usize],
                gap: state.gap,
                lambda_n: state.lambda_n(),
                lambda_t: state.lambda_t_norm(),
                area,
                pressure: -state.lambda_n() / area.max(f64::MIN_POSITIVE),
                work: state.work,
                slip: state.slip,
                mu: state.mu,
            }
        })
        .collect())
}

/// One [`ContactNode`] per candidate node of a tool.
fn contact_nodes(s: &mut ScriptSim, name: &str) -> ScriptResult<Array> {
    Ok(candidates(s, name)?
        .into_iter()
        .map(Dynamic::from)
        .collect())
}

/// A node's history against a tool: one record (src/script/record.rs) per converged
/// increment, read like a map of `increment, time, work, mu, status`.
fn node_history(s: &mut ScriptSim, name: &str, node: i64) -> ScriptResult<Array> {
    let mut st = s.borrow_mut();
    let sim = st.simulation()?;
    let c = lift(sim.model.tool_index(name))?;
    let Some(k) = sim.model.contacts[c]
        .candidates
        .iter()
        .position(|&n| n as i64 == node)
    else {
        return runtime_error(format!(
            "node {node} is not a contact candidate of tool '{name}'"
        ));
    };
    Ok(st
        .node_log()
        .iter()
        .map(|(index, time, tools)| {
            let [work, mu, status] = tools[c][k];
            let mut m = Map::new();
            m.insert("increment".into(), Dynamic::from(*index as i64));
            m.insert("time".into(), Dynamic::from(*time));
            m.insert("work".into(), Dynamic::from(work));
            m.insert("mu".into(), Dynamic::from(mu));
            m.insert(
                "status".into(),
                Dynamic::from(STATUS[status as usize].to_string()),
            );
            Dynamic::from(super::record::Record::new(m))
        })
        .collect())
}
