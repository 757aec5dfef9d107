//! Charts and summary entries for scripts: `line_chart(file, spec)`,
//! `sim.chart_field(file, face_set, field, options)`, `sim.chart_tool_field(file, tool,
//! field, options)` and `sim.summary(key, value)`.
//! Chart files go below the run's output folder (relative paths only, no `..`), each with a
//! CSV of its data beside it.

use super::api_sim::ScriptSim;
use super::convert::*;
use super::HostOptions;
use crate::output::field_chart::{field_map, law_range, Configuration, MapView};
use crate::output::svg::{LineChart, Series};
use crate::output::OutputFolder;
use rhai::{Array, Dynamic, Engine, Map};
use std::path::PathBuf;
use std::rc::Rc;

/// `file` below the output folder, ending in .svg, parent folders created.
fn chart_path(host: &HostOptions, file: &str) -> ScriptResult<PathBuf> {
    if !file.ends_with(".svg") {
        return runtime_error(format!("chart file \"{file}\" must end in .svg"));
    }
    lift(OutputFolder::create(&host.out_dir).and_then(|f| f.resolve_for_write(file)))
}

fn string(v: &Dynamic, what: &str) -> ScriptResult<String> {
    v.clone()
        .into_string()
        .map_err(|t| format!("{what} must be a string, got {t}"))
        .or_else(runtime_error)
}

fn numbers(v: &Dynamic, what: &str) -> ScriptResult<Vec<f64>> {
    let a = v
        .clone()
        .try_cast::<Array>()
        .ok_or_else(|| format!("{what} must be an array of numbers, got {}", v.type_name()))
        .or_else(runtime_error)?;
    a.iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{what}[{i}]")))
        .collect()
}

fn line_chart_spec(spec: &Map) -> ScriptResult<LineChart> {
    let mut chart = LineChart::default();
    for (key, v) in spec {
        match key.as_str() {
            "title" => chart.title = string(v, "line chart title")?,
            "x_label" => chart.x_label = string(v, "x_label")?,
            "y_label" => chart.y_label = string(v, "y_label")?,
            "series" => {
                let list = v
                    .clone()
                    .try_cast::<Array>()
                    .ok_or_else(|| "series must be an array of #{ name, x, y } maps".to_string())
                    .or_else(runtime_error)?;
                for (i, s) in list.iter().enumerate() {
                    let m = s
                        .clone()
                        .try_cast::<Map>()
                        .ok_or_else(|| format!("series[{i}] must be a map #{{ name, x, y }}"))
                        .or_else(runtime_error)?;
                    let get = |k: &str| {
                        m.get(k)
                            .ok_or_else(|| format!("series[{i}] has no '{k}'"))
                            .or_else(runtime_error)
                    };
                    if let Some(k) = m.keys().find(|k| !["name", "x", "y"].contains(&k.as_str())) {
                        return runtime_error(format!(
                            "series[{i}]: unknown key '{k}' (known: name, x, y)"
                        ));
                    }
                    chart.series.push(Series {
                        name: string(get("name")?, &format!("series[{i}].name"))?,
                        x: numbers(get("x")?, &format!("series[{i}].x"))?,
                        y: numbers(get("y")?, &format!("series[{i}].y"))?,
                    });
                }
            }
            other => {
                return runtime_error(format!(
                    "unknown line chart key '{other}' (known: title, x_label, y_label, series)"
                ))
            }
        }
    }
    // Axis ticks and pixel positions are differences and multiples of the data: values near
    // the end of the f64 range would overflow to inf and NaN there.
    for (i, s) in chart.series.iter().enumerate() {
        for (axis, values) in [("x", &s.x), ("y", &s.y)] {
            if let Some((j, v)) = values
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.abs() <= CHART_LIMIT))
            {
                return fail(crate::Error::input(
                    &format!("series[{i}].{axis}[{j}]"),
                    v,
                    &format!(
                        "must be finite and at most {CHART_LIMIT:e} in magnitude to be charted"
                    ),
                ));
            }
        }
    }
    Ok(chart)
}

/// The map of tool `tool`'s tool-side field `field` at the committed state: an error
/// naming the tool when it has no tool-side fields (no `tool.wear(...)`).
fn tool_map(
    sim: &crate::solver::Simulation,
    tool: &str,
    field: &str,
) -> crate::Result<crate::output::tool_map::ToolMap> {
    let c = sim.model.tool_index(tool)?;
    let surface = sim.model.contacts[c].tool.surface.as_patch_surface();
    let (Some(fields), Some(surface)) = (sim.tool_fields(c), surface) else {
        return Err(crate::Error::Input(format!(
            "tool '{tool}' has no tool-side fields (give it tool.wear(archard(k, H)))"
        )));
    };
    let pose = sim.tool_pose(c);
    crate::output::tool_map::ToolMap::new(tool, surface, fields, &pose, field, sim.time())
}

/// The colour range of a field map: the drawn values', a fixed one, or the friction law's.
enum Range {
    Data,
    Fixed(f64, f64),
    Law,
}

/// Largest magnitude a chart accepts.
const CHART_LIMIT: f64 = 1e300;

pub fn register(engine: &mut Engine, host: Rc<HostOptions>) {
    let h = host.clone();
    engine.register_fn(
        "line_chart",
        move |file: &str, spec: Map| -> ScriptResult<()> {
            let chart = line_chart_spec(&spec)?;
            lift(chart.write(&chart_path(&h, file)?).map(|_| ()))
        },
    );
    let h = host.clone();
    engine.register_fn(
        "chart_field",
        move |s: &mut ScriptSim, file: &str, face_set: &str, field: &str, options: Map| -> ScriptResult<()> {
            let mut view = MapView::default();
            let (mut title, mut label) = (None, None);
            let mut range = Range::Data;
            for (key, v) in &options {
                match key.as_str() {
                    "title" => title = Some(string(&v, "chart title")?),
                    "label" => label = Some(string(v, "colour bar label")?),
                    "tool" => view.tool = Some(string(v, "tool")?),
                    "configuration" => {
                        view.configuration = lift(Configuration::parse(&string(v, "configuration")?))?
                    }
                    "range" if v.is_string() => {
                        let name = string(v, "range")?;
                        if name != "law" {
                            return runtime_error(format!("range = \"{name}\" must be \"law\" or [low, high]"));
                        }
                        range = Range::Law;
                    }
                    "range" => {
                        let r = numbers(v, "range")?;
                        if r.len() != 2 {
                            return runtime_error(format!("range must be [low, high] or \"law\", got {} numbers", r.len()));
                        }
                        range = Range::Fixed(r[0], r[1]);
                    }
                    other => {
                        return runtime_error(format!(
                            "unknown chart_field option '{other}' (known: title, label, range, configuration, tool)"
                        ))
                    }
                }
            }
            let path = chart_path(&h, file)?;
            let mut st = s.borrow_mut();
            view.length_unit = st.length_unit();
            view.formability = st.formability();
            let sim = st.simulation()?;
            let mut map = lift(field_map(sim, face_set, field, &view))?;
            map.title = title.unwrap_or(map.title);
            map.label = label.unwrap_or(map.label);
            map.range = match range {
                Range::Data => None,
                Range::Fixed(lo, hi) => Some((lo, hi)),
                Range::Law => Some(lift(law_range(sim, field, view.tool.as_deref()))?),
            };
            lift(map.write(&path).map(|_| ()))
        },
    );
    engine.register_fn(
        "chart_field",
        |ctx: rhai::NativeCallContext,
         s: &mut ScriptSim,
         file: &str,
         face_set: &str,
         field: &str|
         -> ScriptResult<()> {
            ctx.call_native_fn(
                "chart_field",
                (
                    s.clone(),
                    file.to_string(),
                    face_set.to_string(),
                    field.to_string(),
                    Map::new(),
                ),
            )
        },
    );
    let h = host.clone();
    engine.register_fn(
        "chart_tool_field",
        move |s: &mut ScriptSim,
              file: &str,
              tool: &str,
              field: &str,
              options: Map|
              -> ScriptResult<()> {
            let path = chart_path(&h, file)?;
            let mut st = s.borrow_mut();
            let unit = st.length_unit();
            let sim = st.simulation()?;
            let mut m = lift(tool_map(sim, tool, field))?;
            let axis = |name: &str| {
                if unit.is_empty() {
                    name.to_string()
                } else {
                    format!("{name} [{unit}]")
                }
            };
            (m.map.x_label, m.map.y_label) = (axis("x"), axis("y"));
            for (key, v) in &options {
                match key.as_str() {
                    "title" => m.map.title = string(v, "chart title")?,
                    "label" => m.map.label = string(v, "colour bar label")?,
                    "range" => {
                        let r = numbers(v, "range")?;
                        if r.len() != 2 {
                            return runtime_error(format!(
                                "range must be [low, high], got {} numbers",
                                r.len()
                            ));
                        }
                        m.map.range = Some((r[0], r[1]));
                    }
                    other => {
                        return runtime_error(format!(
                            "unknown chart_tool_field option '{other}' (known: title, label, range)"
                        ))
                    }
                }
            }
            lift(m.write(&path).map(|_| ()))
        },
    );
    engine.register_fn(
        "chart_tool_field",
        |ctx: rhai::NativeCallContext,
         s: &mut ScriptSim,
         file: &str,
         tool: &str,
         field: &str|
         -> ScriptResult<()> {
            ctx.call_native_fn(
                "chart_tool_field",
                (
                    s.clone(),
                    file.to_string(),
                    tool.to_string(),
                    field.to_string(),
                    Map::new(),
                ),
            )
        },
    );
    let h = host.clone();
    engine.register_fn(
        "chart_fld",
        move |s: &mut ScriptSim, file: &str, options: Map| -> ScriptResult<()> {
            let (mut title, mut subtitle) = (None, None);
            for (k, v) in options {
                match k.as_str() {
                    "title" => title = Some(string(&v, "chart title")?),
                    "subtitle" => subtitle = Some(string(&v, "chart subtitle")?),
                    other => {
                        return runtime_error(format!(
                            "unknown chart_fld option '{other}' (known: title, subtitle)"
                        ))
                    }
                }
            }
            let path = chart_path(&h, file)?;
            let mut st = s.borrow_mut();
            let options = st.formability();
            let time_unit = st.time_unit();
            let sim = st.simulation()?;
            let Some(f) = crate::output::formability::evaluate(sim, &options) else {
                return runtime_error(
                    "chart_fld: the mesh has no through-thickness node columns (no sheet), so no \
                     forming limit diagram",
                );
            };
            let unit = if time_unit.is_empty() {
                String::new()
            } else {
                format!(" {time_unit}")
            };
            let chart = crate::output::fld_chart::FldChart {
                title: title.unwrap_or_else(|| {
                    format!(
                        "Forming limit diagram, t = {}{unit}",
                        crate::output::significant(sim.time(), 6)
                    )
                }),
                subtitle: subtitle.unwrap_or_else(|| sim.model.material.describe()),
                formability: &f,
                safety_margin: options.thresholds.safety_margin,
            };
            lift(chart.write(&path).map(|_| ()))
        },
    );
    engine.register_fn(
        "chart_fld",
        |ctx: rhai::NativeCallContext, s: &mut ScriptSim, file: &str| -> ScriptResult<()> {
            ctx.call_native_fn("chart_fld", (s.clone(), file.to_string(), Map::new()))
        },
    );
    engine.register_fn(
        "summary",
        |s: &mut ScriptSim, key: &str, value: Dynamic| -> ScriptResult<()> {
            if key.is_empty() {
                return runtime_error("a summary entry needs a non-empty name");
            }
            let json = to_json(&value, key, JsonUse::Summary)?;
            s.borrow_mut().add_summary_entry(key, json)
        },
    );
}
