//! The study's two chart kinds, as standalone SVG: a log-log work-precision chart (error
//! against wall time, one marked polyline per family, each point labelled) and a grid of
//! outcome cells (one panel per friction coefficient and method; rows the augmentation
//! parameter, columns the step size; the colour says how the run ended, the number its
//! Newton iterations).
//!
//! Log axes span whole decades around the data; a point with a non-positive value (an
//! error of exactly 0) cannot be drawn on them and is left out of the picture (it stays
//! in the CSV).

use super::Outcome;
use crate::output::svg::{text, FONT, PALETTE};
use std::fmt::Write as _;

/// One family of a work-precision chart: (x, y, label) points in the order to join them.
pub struct LogSeries {
    pub name: String,
    pub points: Vec<(f64, f64, String)>,
}

fn decade_label(k: i32) -> String {
    match k {
        -2..=3 => format!("{}", 10f64.powi(k)),
        _ => format!("1e{k}"),
    }
}

/// Whole decades [lo, hi] holding the positive finite values (at least one decade).
fn decades(values: impl Iterator<Item = f64>) -> (i32, i32) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0, 1);
    }
    let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (a, b.max(a + 1))
}

/// A log-log chart of the series, with dashed horizontal lines (value, label).
pub fn log_log(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[LogSeries],
    hlines: &[(f64, &str)],
) -> String {
    let (width, height) = (1040.0, 560.0);
    let (left, right, top, bottom) = (80.0, 690.0, 50.0, 500.0);
    let drawable =
        |p: &&(f64, f64, String)| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite();
    let (x0, x1) = decades(
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(drawable).map(|p| p.0)),
    );
    let (y0, y1) = decades(
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(drawable).map(|p| p.1))
            .chain(hlines.iter().map(|h| h.0)),
    );
    let sx = |x: f64| left + (x.log10() - x0 as f64) / (x1 - x0) as f64 * (right - left);
    let sy = |y: f64| bottom - (y.log10() - y0 as f64) / (y1 - y0) as f64 * (bottom - top);
    let mut o = String::new();
    let _ = writeln!(
        o,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\" {FONT}>"
    );
    let _ = writeln!(o, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    text(
        &mut o,
        (left + right) / 2.0,
        28.0,
        16.0,
        "middle",
        "",
        title,
    );
    for k in x0..=x1 {
        let x = sx(10f64.powi(k));
        let _ = writeln!(
            o,
            "<line x1=\"{x:.1}\" y1=\"{top}\" x2=\"{x:.1}\" y2=\"{bottom}\" stroke=\"#dddddd\"/>"
        );
        text(
            &mut o,
            x,
            bottom + 18.0,
            12.0,
            "middle",
            "",
            &decade_label(k),
        );
    }
    for k in y0..=y1 {
        let y = sy(10f64.powi(k));
        let _ = writeln!(
            o,
            "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{right}\" y2=\"{y:.1}\" stroke=\"#dddddd\"/>"
        );
        text(
            &mut o,
            left - 6.0,
            y + 4.0,
            12.0,
            "end",
            "",
            &decade_label(k),
        );
    }
    let _ = writeln!(
        o,
        "<rect x=\"{left}\" y=\"{top}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>",
        right - left,
        bottom - top
    );
    text(
        &mut o,
        (left + right) / 2.0,
        bottom + 42.0,
        13.0,
        "middle",
        "",
        x_label,
    );
    let yc = (top + bottom) / 2.0;
    let turn = format!(" transform=\"rotate(-90 20 {yc:.1})\"");
    text(&mut o, 20.0, yc, 13.0, "middle", &turn, y_label);
    for &(v, label) in hlines.iter().filter(|h| h.0 > 0.0 && h.0.is_finite()) {
        let y = sy(v);
        let _ = writeln!(o, "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{right}\" y2=\"{y:.1}\" stroke=\"#555555\" stroke-dasharray=\"6 4\"/>");
        text(&mut o, right - 4.0, y - 5.0, 11.0, "end", "", label);
    }
    for (i, s) in series.iter().enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        let pts: Vec<&(f64, f64, String)> = s.points.iter().filter(drawable).collect();
        if pts.len() > 1 {
            let path: Vec<String> = pts
                .iter()
                .map(|p| format!("{:.1},{:.1}", sx(p.0), sy(p.1)))
                .collect();
            let _ = writeln!(
                o,
                "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.5\"/>",
                path.join(" ")
            );
        }
        for (k, p) in pts.iter().enumerate() {
            let (x, y) = (sx(p.0), sy(p.1));
            let _ = writeln!(
                o,
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"3.5\" fill=\"{colour}\"/>"
            );
            // Labels alternate above and below their points: runs of one family often
            // share an error and sit side by side.
            let dy = if k % 2 == 0 { -5.0 } else { 13.0 };
            text(&mut o, x + 5.0, y + dy, 9.0, "start", "", &p.2);
        }
        let ly = top + 10.0 + 18.0 * i as f64;
        let _ = writeln!(o, "<line x1=\"{}\" y1=\"{ly:.1}\" x2=\"{}\" y2=\"{ly:.1}\" stroke=\"{colour}\" stroke-width=\"3\"/>", right + 14.0, right + 34.0);
        text(&mut o, right + 40.0, ly + 4.0, 12.0, "start", "", &s.name);
    }
    o.push_str("</svg>\n");
    o
}

/// One panel of an outcome grid: `cells[row][col]` = (outcome, text shown in the cell).
pub struct Panel {
    pub title: String,
    pub rows: Vec<String>,
    pub cols: Vec<String>,
    pub cells: Vec<Vec<(Outcome, String)>>,
}

pub fn outcome_colour(o: Outcome) -> &'static str {
    match o {
        Outcome::Converged => "#4daf4a",
        Outcome::ConvergedCycling => "#a6d96a",
        Outcome::Cycled => "#fdae61",
        Outcome::Stalled => "#ffd92f",
        Outcome::Diverged => "#d7191c",
    }
}

/// Panels side by side (`per_row` of them per row), each a grid of coloured cells with the
/// iteration count inside; a legend of the outcomes below.
pub fn outcome_grid(
    title: &str,
    row_label: &str,
    col_label: &str,
    panels: &[Panel],
    per_row: usize,
) -> String {
    let (cell_w, cell_h) = (52.0, 30.0);
    let n_rows = panels.iter().map(|p| p.rows.len()).max().unwrap_or(1) as f64;
    let n_cols = panels.iter().map(|p| p.cols.len()).max().unwrap_or(1) as f64;
    let (pad_l, pad_t, gap) = (70.0, 40.0, 30.0);
    let (pad_t, title_lines) = (
        pad_t + 14.0,
        panels
            .iter()
            .map(|p| p.title.lines().count())
            .max()
            .unwrap_or(1) as f64,
    );
    let pad_t = pad_t + 14.0 * (title_lines - 1.0);
    let panel_w = (pad_l + n_cols * cell_w + gap).max(330.0);
    let panel_h = pad_t + n_rows * cell_h + 50.0;
    let per_row = per_row.max(1);
    let grid_rows = panels.len().div_ceil(per_row).max(1) as f64;
    let width = 20.0 + per_row.min(panels.len().max(1)) as f64 * panel_w;
    let height = 50.0 + grid_rows * panel_h + 60.0;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" height=\"{height:.0}\" viewBox=\"0 0 {width:.0} {height:.0}\" {FONT}>"
    );
    let _ = writeln!(o, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    text(&mut o, width / 2.0, 26.0, 16.0, "middle", "", title);
    for (i, p) in panels.iter().enumerate() {
        let ox = 20.0 + (i % per_row) as f64 * panel_w;
        let oy = 50.0 + (i / per_row) as f64 * panel_h;
        for (k, line) in p.title.lines().enumerate() {
            let cx = ox + pad_l + p.cols.len() as f64 * cell_w / 2.0;
            text(
                &mut o,
                cx,
                oy + 14.0 + 16.0 * k as f64,
                13.0,
                "middle",
                "",
                line,
            );
        }
        for (r, row) in p.cells.iter().enumerate() {
            let y = oy + pad_t + r as f64 * cell_h;
            text(
                &mut o,
                ox + pad_l - 6.0,
                y + cell_h / 2.0 + 4.0,
                11.0,
                "end",
                "",
                &p.rows[r],
            );
            for (c, (outcome, label)) in row.iter().enumerate() {
                let outcome = *outcome;
                let x = ox + pad_l + c as f64 * cell_w;
                let _ = writeln!(
                    o,
                    "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{cell_w}\" height=\"{cell_h}\" fill=\"{}\" stroke=\"white\"><title>{}</title></rect>",
                    outcome_colour(outcome),
                    outcome.name()
                );
                text(
                    &mut o,
                    x + cell_w / 2.0,
                    y + cell_h / 2.0 + 4.0,
                    11.0,
                    "middle",
                    "",
                    label,
                );
            }
        }
        let yb = oy + pad_t + p.rows.len() as f64 * cell_h;
        for (c, label) in p.cols.iter().enumerate() {
            text(
                &mut o,
                ox + pad_l + (c as f64 + 0.5) * cell_w,
                yb + 14.0,
                11.0,
                "middle",
                "",
                label,
            );
        }
        text(
            &mut o,
            ox + pad_l + p.cols.len() as f64 * cell_w / 2.0,
            yb + 30.0,
            11.0,
            "middle",
            "",
            col_label,
        );
        let (rx, ry) = (ox + 10.0, oy + pad_t + p.rows.len() as f64 * cell_h / 2.0);
        let turn = format!(" transform=\"rotate(-90 {rx:.1} {ry:.1})\"");
        text(&mut o, rx, ry, 11.0, "middle", &turn, row_label);
    }
    let ly = height - 40.0;
    let all = [
        Outcome::Converged,
        Outcome::ConvergedCycling,
        Outcome::Cycled,
        Outcome::Stalled,
        Outcome::Diverged,
    ];
    let mut x = 20.0;
    for outcome in all {
        let _ = writeln!(
            o,
            "<rect x=\"{x:.1}\" y=\"{:.1}\" width=\"14\" height=\"14\" fill=\"{}\"/>",
            ly - 11.0,
            outcome_colour(outcome)
        );
        text(&mut o, x + 18.0, ly, 11.0, "start", "", outcome.name());
        x += 24.0 + 6.5 * outcome.name().len() as f64;
    }
    text(
        &mut o,
        20.0,
        ly + 20.0,
        11.0,
        "start",
        "",
        "number: Newton iterations of the whole run; iN: the run failed in increment N",
    );
    o.push_str("</svg>\n");
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decades_cover_the_data() {
        assert_eq!(decades([0.003, 0.2].into_iter()), (-3, 0));
        assert_eq!(decades([5.0].into_iter()), (0, 1));
        assert_eq!(decades([0.0, f64::NAN].into_iter()), (0, 1));
    }

    #[test]
    fn charts_are_closed_svg_documents() {
        let s = log_log(
            "t <1>",
            "x",
            "y",
            &[LogSeries {
                name: "a".into(),
                points: vec![(1.0, 0.1, "p".into()), (2.0, 0.0, "zero".into())],
            }],
            &[(0.01, "1 %"), (0.003, "band")],
        );
        assert!(s.contains(">band<"));
        assert!(s.starts_with("<svg") && s.ends_with("</svg>\n"));
        assert!(s.contains("t &lt;1&gt;"));
        assert!(
            !s.contains(">zero<"),
            "a zero error is not drawn on a log axis"
        );
        let g = outcome_grid(
            "g",
            "r",
            "dt",
            &[Panel {
                title: "p".into(),
                rows: vec!["1".into()],
                cols: vec!["a".into(), "b".into()],
                cells: vec![vec![
                    (Outcome::Converged, "3".into()),
                    (Outcome::Diverged, "i2".into()),
                ]],
            }],
            2,
        );
        assert!(g.contains(outcome_colour(Outcome::Diverged)) && g.ends_with("</svg>\n"));
    }
}
