//! `tribo sweep collect DIR`: every run's summary.json in one table, and charts of chosen
//! outputs against a chosen parameter.
//!
//! `collected.csv` has one row per run of `sweep.csv`: the run id, the parameters, then
//! every value of the summaries, nested keys joined with `.` and array items numbered
//! (`tools.roller.final_force.2`), columns in the order they first appear. A run without a
//! summary.json (not run yet, or killed) keeps its row with `status` = `missing`.
//!
//! A chart `chart_Y_vs_X.svg` (with its CSV, the project's line chart) per output `Y`: `X`
//! a numeric parameter on the x axis, one line per value of the other parameters (or of
//! `series`), points in increasing `X`.

use super::{csv_cell, table::Table, INDEX_FILE};
use crate::output::svg::{LineChart, Series};
use crate::{Error, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};

pub const COLLECTED_FILE: &str = "collected.csv";

/// What to chart.
#[derive(Clone, Debug, Default)]
pub struct ChartSpec {
    /// Parameter on the x axis (default: the table's first column).
    pub x: Option<String>,
    /// Outputs on the y axis, one chart each (default: `newton_iterations`).
    pub y: Vec<String>,
    /// Parameters whose values make the lines (default: every other parameter).
    pub series: Vec<String>,
}

/// The runs' table: parameters and flattened summaries.
#[derive(Clone, Debug)]
pub struct Collected {
    pub parameters: Vec<String>,
    pub outputs: Vec<String>,
    /// Per run: id, parameter values, output values (`None`: absent in that summary).
    pub rows: Vec<(String, Vec<String>, Vec<Option<String>>)>,
}

impl Collected {
    /// Reads `DIR/sweep.csv` and every run's summary.json.
    pub fn read(dir: &Path) -> Result<Collected> {
        let index = Table::read(&dir.join(INDEX_FILE))?;
        if index.columns.len() < 2 || index.columns[0] != "id" || index.columns[1] != "folder" {
            return Err(Error::Input(format!(
                "{}: not a sweep index (its header must start with id,folder)",
                dir.join(INDEX_FILE).display()
            )));
        }
        let parameters = index.columns[2..].to_vec();
        let mut outputs: Vec<String> = Vec::new();
        let mut flat_rows = Vec::new();
        for row in &index.rows {
            let path = dir.join(&row[1]).join(crate::output::SUMMARY_FILE);
            let flat = match std::fs::read_to_string(&path) {
                Ok(text) => {
                    let value: Value = serde_json::from_str(&text).map_err(|e| {
                        Error::Input(format!("{}:{}: {e}", path.display(), e.line()))
                    })?;
                    let mut flat = Vec::new();
                    flatten("", &value, &mut flat);
                    flat
                }
                Err(_) => vec![("status".to_string(), "missing".to_string())],
            };
            for (k, _) in &flat {
                if !outputs.contains(k) {
                    outputs.push(k.clone());
                }
            }
            flat_rows.push((row[0].clone(), row[2..].to_vec(), flat));
        }
        let rows = flat_rows
            .into_iter()
            .map(|(id, params, flat)| {
                let values = outputs
                    .iter()
                    .map(|o| flat.iter().find(|(k, _)| k == o).map(|(_, v)| v.clone()))
                    .collect();
                (id, params, values)
            })
            .collect();
        Ok(Collected {
            parameters,
            outputs,
            rows,
        })
    }

    pub fn to_csv(&self) -> String {
        let mut header = vec!["id".to_string()];
        header.extend(self.parameters.iter().map(|p| csv_cell(p)));
        header.extend(self.outputs.iter().map(|o| csv_cell(o)));
        let mut text = header.join(",") + "\n";
        for (id, params, values) in &self.rows {
            let mut cells = vec![csv_cell(id)];
            cells.extend(params.iter().map(|p| csv_cell(p)));
            cells.extend(values.iter().map(|v| csv_cell(v.as_deref().unwrap_or(""))));
            text.push_str(&cells.join(","));
            text.push('\n');
        }
        text
    }

    /// The chart of output `y` against parameter `x`, one line per value of `series`.
    pub fn chart(&self, x: &str, y: &str, series: &[String]) -> Result<LineChart> {
        let param = |name: &str| {
            self.parameters
                .iter()
                .position(|p| p == name)
                .ok_or_else(|| {
                    Error::Input(format!(
                        "'{name}' is not a parameter of the sweep ({})",
                        self.parameters.join(", ")
                    ))
                })
        };
        let xi = param(x)?;
        let si = series
            .iter()
            .map(|s| param(s))
            .collect::<Result<Vec<_>>>()?;
        let yi = self.outputs.iter().position(|o| o == y).ok_or_else(|| {
            Error::Input(format!(
                "'{y}' is not in the summaries (collected.csv lists them all)"
            ))
        })?;
        let number = |text: &str, what: &str, id: &str| {
            text.parse::<f64>()
                .map_err(|_| Error::Input(format!("{id}: {what} = '{text}' is not a number")))
        };
        let mut lines: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for (id, params, values) in &self.rows {
            let Some(v) = values[yi].as_deref() else {
                continue;
            };
            let point = (number(&params[xi], x, id)?, number(v, y, id)?);
            let name = si
                .iter()
                .map(|&s| format!("{} = {}", self.parameters[s], params[s]))
                .collect::<Vec<_>>()
                .join(", ");
            match lines.iter_mut().find(|(n, _)| *n == name) {
                Some((_, points)) => points.push(point),
                None => lines.push((name, vec![point])),
            }
        }
        let series = lines
            .into_iter()
            .map(|(name, mut points)| {
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                Series {
                    name: if name.is_empty() { y.to_string() } else { name },
                    x: points.iter().map(|p| p.0).collect(),
                    y: points.iter().map(|p| p.1).collect(),
                }
            })
            .collect();
        Ok(LineChart {
            title: format!("{y} against {x}"),
            x_label: x.to_string(),
            y_label: y.to_string(),
            series,
        })
    }
}

/// Nested keys joined with `.`, array items numbered; strings without quotes, null empty.
fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, String)>) {
    let key = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                flatten(&key(k), v, out);
            }
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                flatten(&key(&i.to_string()), v, out);
            }
        }
        Value::String(s) => out.push((prefix.to_string(), s.clone())),
        Value::Null => out.push((prefix.to_string(), String::new())),
        other => out.push((prefix.to_string(), other.to_string())),
    }
}

/// Writes `DIR/collected.csv` and the charts; returns the files written.
pub fn run(dir: &Path, spec: &ChartSpec) -> Result<Vec<PathBuf>> {
    let collected = Collected::read(dir)?;
    let table = dir.join(COLLECTED_FILE);
    crate::output::write_atomic(&table, collected.to_csv().as_bytes())?;
    let mut written = vec![table];
    let x = match &spec.x {
        Some(x) => x.clone(),
        None => collected.parameters[0].clone(),
    };
    let series: Vec<String> = if spec.series.is_empty() {
        collected
            .parameters
            .iter()
            .filter(|p| **p != x)
            .cloned()
            .collect()
    } else {
        spec.series.clone()
    };
    let outputs = if spec.y.is_empty() {
        vec!["newton_iterations".to_string()]
    } else {
        spec.y.clone()
    };
    for y in &outputs {
        let chart = collected.chart(&x, y, &series)?;
        let file: String = format!("chart_{y}_vs_{x}")
            .chars()
            .map(|c| {
                if c.is_alphanumeric() || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let svg = dir.join(format!("{file}.svg"));
        chart.write(&svg)?;
        written.push(svg);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summaries_flatten_to_dotted_columns() {
        let v: Value = serde_json::from_str(
            r#"{"status": "finished", "tools": {"roller": {"final_force": [1.5, 0, -2]}}, "error": null}"#,
        )
        .unwrap();
        let mut flat = Vec::new();
        flatten("", &v, &mut flat);
        let keys: Vec<&str> = flat.iter().map(|(k, _)| k.as_str()).collect();
        assert!(keys.contains(&"tools.roller.final_force.2"));
        assert!(flat.contains(&("tools.roller.final_force.0".into(), "1.5".into())));
        assert!(flat.contains(&("error".into(), String::new())));
        assert!(flat.contains(&("status".into(), "finished".into())));
    }
}
