//! How the REPL shows a value: floats to 6 significant digits (what a person reads; the
//! value itself keeps full precision and `print(x)` shows it all), and an increment report
//! (`sim.step()`) as one line instead of a 14-key map.

use rhai::{Dynamic, Map};

/// Significant digits of floats shown at the prompt.
const DIGITS: i32 = 6;

/// `v` to [`DIGITS`] significant digits, in plain notation from 1e-5 to 1e6 and in
/// exponent notation outside; a float always shows a `.` or an exponent (`2.0`, not `2`)
/// so it is not mistaken for an integer.
pub fn float(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return if v.is_sign_negative() { "-0.0" } else { "0.0" }.into();
    }
    let exponent = v.abs().log10().floor() as i32;
    if (-5..6).contains(&exponent) {
        let decimals = (DIGITS - 1 - exponent).max(0) as usize;
        let mut s = format!("{v:.decimals$}");
        if s.contains('.') {
            s = s.trim_end_matches('0').trim_end_matches('.').to_string();
        }
        if !s.contains('.') {
            s.push_str(".0");
        }
        s
    } else {
        let s = format!("{:.*e}", (DIGITS - 1) as usize, v);
        let (mantissa, exp) = s.split_once('e').expect("exponent notation");
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{exp}")
    }
}

/// A value as the REPL prints it (Rhai's own notation, floats shortened).
pub fn value(v: &Dynamic) -> String {
    if let Ok(f) = v.as_float() {
        float(f)
    } else if let Some(s) = v.read_lock::<rhai::ImmutableString>() {
        format!("{:?}", s.as_str())
    } else if let Some(a) = v.read_lock::<rhai::Array>() {
        let items: Vec<String> = a.iter().map(value).collect();
        format!("[{}]", items.join(", "))
    } else if let Some(m) = v.read_lock::<Map>() {
        let items: Vec<String> = m
            .iter()
            .map(|(k, x)| format!("{:?}: {}", k.as_str(), value(x)))
            .collect();
        format!("#{{{}}}", items.join(", "))
    } else if let Some(n) = v.read_lock::<crate::script::api_contact::ContactNode>() {
        // A contact-node record shows as the map it reads like.
        value(&Dynamic::from(n.to_map()))
    } else if let Some(r) = v.read_lock::<crate::script::record::Record>() {
        // So does a record of sim.history() or sim.node_history().
        value(&Dynamic::from(r.map().clone()))
    } else {
        v.to_string()
    }
}

/// Whether a map is an increment report (`sim.step()`, `sim.run()`, `sim.history()[i]`).
pub fn is_report(m: &Map) -> bool {
    [
        "index",
        "time",
        "dt",
        "iterations",
        "cutbacks",
        "residuals",
        "active_nodes",
    ]
    .iter()
    .all(|k| m.contains_key(*k))
}

/// One line for an increment report: its index and time, where the tools are
/// (`positions`, from the simulation), Newton iterations and the last iteration's
/// residuals, cutbacks and contact nodes.
pub fn report_line(m: &Map, positions: &[(String, [f64; 3])]) -> String {
    let get = |k: &str| m.get(k).cloned().unwrap_or(Dynamic::UNIT);
    let int = |k: &str| get(k).as_int().unwrap_or(0);
    let num = |k: &str| get(k).as_float().unwrap_or(f64::NAN);
    let mut line = format!(
        "increment {}: t = {} (dt {})",
        int("index"),
        float(num("time")),
        float(num("dt"))
    );
    for (name, p) in positions {
        line.push_str(&format!(
            ", {name} at [{}, {}, {}]",
            float(p[0]),
            float(p[1]),
            float(p[2])
        ));
    }
    line.push_str(&format!("; {} iterations", int("iterations")));
    let last = get("residuals")
        .into_array()
        .ok()
        .and_then(|r| r.last().cloned())
        .and_then(|r| r.into_array().ok());
    if let Some(r) = last {
        let at = |i: usize| r.get(i).and_then(|x| x.as_float().ok()).unwrap_or(f64::NAN);
        line.push_str(&format!(
            ", residuals {} (force, relative) {} (contact)",
            float(at(0)),
            float(at(1))
        ));
    }
    line.push_str(&format!(
        "; {} cutbacks; {} active nodes ({} slipping)",
        int("cutbacks"),
        int("active_nodes"),
        int("slipping_nodes")
    ));
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn six_significant_digits() {
        assert_eq!(float(0.30000000000000004), "0.3");
        assert_eq!(float(-23.912345678), "-23.9123");
        assert_eq!(float(2.0), "2.0");
        assert_eq!(float(123456.7), "123457.0");
        assert_eq!(float(1234567.0), "1.23457e6");
        assert_eq!(float(1.5e-12), "1.5e-12");
        assert_eq!(float(0.000123456789), "0.000123457");
        assert_eq!(float(-0.0), "-0.0");
        assert_eq!(float(f64::NAN), "NaN");
    }

    #[test]
    fn nested_values_and_report_line() {
        let a: rhai::Array = vec![Dynamic::from(0.1 + 0.2), Dynamic::from(3_i64), "x".into()];
        assert_eq!(value(&Dynamic::from(a)), "[0.3, 3, \"x\"]");
        let mut m = Map::new();
        for (k, v) in [("index", 2_i64), ("iterations", 4), ("cutbacks", 1)] {
            m.insert(k.into(), Dynamic::from(v));
        }
        m.insert("active_nodes".into(), Dynamic::from(7_i64));
        m.insert("slipping_nodes".into(), Dynamic::from(3_i64));
        m.insert("time".into(), Dynamic::from(0.2));
        m.insert("dt".into(), Dynamic::from(0.1));
        let res: rhai::Array = vec![
            Dynamic::from(vec![Dynamic::from(1.0), Dynamic::from(0.5)]),
            Dynamic::from(vec![Dynamic::from(2.5e-11), Dynamic::from(0.0)]),
        ];
        m.insert("residuals".into(), Dynamic::from(res));
        assert!(is_report(&m));
        assert_eq!(
            report_line(&m, &[("roller".into(), [0.1, 0.0, -0.12])]),
            "increment 2: t = 0.2 (dt 0.1), roller at [0.1, 0.0, -0.12]; 4 iterations, residuals 2.5e-11 (force, relative) 0.0 (contact); 1 cutbacks; 7 active nodes (3 slipping)"
        );
    }
}
