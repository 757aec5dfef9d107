//! Standalone SVG charts: a line chart of x-y series and a top view colour map of a nodal
//! field on quadrilateral faces. Each chart is written with a CSV of its data beside it
//! (`name.svg` and `name.csv`) so that the numbers behind a picture can be re-plotted.
//!
//! Axis ticks are "nice" numbers: the step is 1, 2 or 5 times a power of ten, the smallest
//! such step giving at most the requested number of intervals over the data range.
//!
//! Colour map: viridis (perceptually uniform, readable in grey and by colour-blind readers),
//! from the nine anchors of `viridisLite::viridis(9)` with linear interpolation in sRGB
//! between them. The colour bar is an SVG gradient with stops at the same anchors, so it
//! shows exactly the colours of the map. A face is split into `n x n` sub-quads (bilinear in
//! position), each filled with the colour of the bilinear value at its centre, so that the
//! picture shows the field's variation inside each face; `n` is chosen to keep the file
//! below about 20 000 polygons.

use super::{fmt_f64, write_atomic, xml_escape};
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One named x-y series of a line chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub name: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
}

/// A line chart: title, axis labels and series.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// A nodal scalar field on quadrilateral faces, seen from above (x right, y up).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FieldMap {
    pub title: String,
    /// Name of the field, shown on the colour bar.
    pub label: String,
    /// In-plane position of every node (only nodes used by `quads` matter).
    pub points: Vec<[f64; 2]>,
    /// Value of the field at every node (NaN: no value, drawn grey).
    pub values: Vec<f64>,
    /// Faces as 4 node indices, in order around the face.
    pub quads: Vec<[usize; 4]>,
    /// Fixed colour range; `None` spans the values of the drawn nodes.
    pub range: Option<(f64, f64)>,
}

/// Nine anchors of viridis, evenly spaced in [0, 1] (viridisLite::viridis(9)).
const VIRIDIS: [[u8; 3]; 9] = [
    [0x44, 0x01, 0x54],
    [0x47, 0x2d, 0x7b],
    [0x3b, 0x52, 0x8b],
    [0x2c, 0x72, 0x8e],
    [0x21, 0x90, 0x8c],
    [0x27, 0xad, 0x81],
    [0x5d, 0xc8, 0x63],
    [0xaa, 0xdc, 0x32],
    [0xfd, 0xe7, 0x25],
];

/// Colours of the series, in order (matplotlib's tab10, cycled).
pub(crate) const PALETTE: [&str; 10] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];

/// Font of every chart, set once on the `<svg>` element.
pub(crate) const FONT: &str = "font-family=\"Helvetica, Arial, sans-serif\"";
/// Colour of a node without a value.
const NO_VALUE: &str = "#bdbdbd";
const MAX_POLYGONS: usize = 20_000;

/// The viridis colour of `t` in [0, 1] (clamped; NaN gives the low end).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (VIRIDIS.len() - 1) as f64;
    let i = (s.floor() as usize).min(VIRIDIS.len() - 2);
    let f = s - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [0, 1, 2].map(|k| (a[k] as f64 + f * (b[k] as f64 - a[k] as f64)).round() as u8)
}

fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// Nice tick values inside `[lo, hi]`: multiples of a step 1, 2 or 5 x 10^k, the smallest
/// such step with at most `max_intervals` intervals over the range. Returns (ticks, step).
pub fn nice_ticks(lo: f64, hi: f64, max_intervals: usize) -> (Vec<f64>, f64) {
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) || max_intervals == 0 {
        return (vec![lo], 1.0);
    }
    let raw = span / max_intervals as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw * (1.0 - 1e-12))
        .unwrap_or(10.0 * mag);
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    let ticks = (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            // Snap round-off (0.30000000000000004) and -0 to the printed value.
            if v.abs() < 1e-9 * step {
                0.0
            } else {
                v
            }
        })
        .collect();
    (ticks, step)
}

/// Tick label: as many decimals as the step needs, exponent form for extreme magnitudes.
pub fn tick_label(v: f64, step: f64) -> String {
    let scale = v.abs().max(step);
    if !(1e-4..1e6).contains(&scale) {
        let digits = ((scale.log10().floor() - step.log10().floor()) as usize).min(6);
        return format!("{v:.digits$e}");
    }
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// Range of the finite values, widened when empty or flat so that axes stay drawable.
fn data_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        (0.0, 1.0)
    } else if lo == hi {
        let pad = if lo == 0.0 { 1.0 } else { 0.5 * lo.abs() };
        (lo - pad, hi + pad)
    } else {
        (lo, hi)
    }
}

/// Axis range widened to the enclosing nice ticks, and its ticks.
fn axis(lo: f64, hi: f64, max_intervals: usize) -> (f64, f64, Vec<f64>, f64) {
    let (_, step) = nice_ticks(lo, hi, max_intervals);
    let (a, b) = ((lo / step).floor() * step, (hi / step).ceil() * step);
    let (ticks, step) = nice_ticks(a, b, max_intervals);
    (a, b, ticks, step)
}

/// `x` in 2 decimals (enough for a pixel grid), never "-0.00".
fn px(x: f64) -> String {
    let s = format!("{x:.2}");
    if s == "-0.00" {
        "0.00".into()
    } else {
        s
    }
}

fn svg_open(out: &mut String, width: f64, height: f64) {
    let _ = write!(
        out,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" {FONT}>\n<rect x=\"0\" y=\"0\" width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n",
        w = px(width),
        h = px(height)
    );
}

/// A `<text>` element; `extra` holds further attributes, each with a leading space.
pub(crate) fn text(
    out: &mut String,
    x: f64,
    y: f64,
    size: f64,
    anchor: &str,
    extra: &str,
    s: &str,
) {
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"{}\" font-size=\"{size}\" text-anchor=\"{anchor}\"{extra}>{}</text>",
        px(x),
        px(y),
        xml_escape(s)
    );
}

/// A y-axis tick label left of the axis at `x_axis`, centred on height `y`.
fn y_tick_label(out: &mut String, x_axis: f64, y: f64, label: &str) {
    text(out, x_axis - 8.0, y + 4.0, 12.0, "end", "", label);
}

impl LineChart {
    fn check(&self) -> Result<()> {
        if self.series.is_empty() {
            return Err(Error::Input(format!(
                "line chart '{}' has no series",
                self.title
            )));
        }
        for s in &self.series {
            if s.x.len() != s.y.len() {
                return Err(Error::Input(format!(
                    "series '{}' of line chart '{}' has {} x values and {} y values",
                    s.name,
                    self.title,
                    s.x.len(),
                    s.y.len()
                )));
            }
        }
        Ok(())
    }

    /// The chart as an SVG document. Non-finite points break a series' line.
    pub fn to_svg(&self) -> Result<String> {
        self.check()?;
        let (width, height) = (760.0, 480.0);
        let legend_w = 12.0
            + 7.0
                * self
                    .series
                    .iter()
                    .map(|s| s.name.chars().count())
                    .max()
                    .unwrap_or(0) as f64;
        let (left, right, top, bottom) = (
            80.0,
            width - 30.0 - legend_w.clamp(60.0, 220.0),
            50.0,
            height - 60.0,
        );
        let (x0, x1, xt, xs) = axis_of(self.series.iter().flat_map(|s| s.x.iter().copied()));
        let (y0, y1, yt, ys) = axis_of(self.series.iter().flat_map(|s| s.y.iter().copied()));
        let sx = |x: f64| left + (x - x0) / (x1 - x0) * (right - left);
        let sy = |y: f64| bottom - (y - y0) / (y1 - y0) * (bottom - top);

        let mut out = String::new();
        svg_open(&mut out, width, height);
        text(
            &mut out,
            (left + right) / 2.0,
            28.0,
            17.0,
            "middle",
            " font-weight=\"bold\"",
            &self.title,
        );
        // Grid and ticks.
        out.push_str("<g stroke=\"#e0e0e0\" stroke-width=\"1\">\n");
        for &t in &xt {
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\"/>",
                px(sx(t)),
                px(top),
                px(bottom)
            );
        }
        for &t in &yt {
            let _ = writeln!(
                out,
                "<line x1=\"{1}\" y1=\"{0}\" x2=\"{2}\" y2=\"{0}\"/>",
                px(sy(t)),
                px(left),
                px(right)
            );
        }
        out.push_str("</g>\n");
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\" stroke-width=\"1\"/>",
            px(left), px(top), px(right - left), px(bottom - top)
        );
        for &t in &xt {
            text(
                &mut out,
                sx(t),
                bottom + 18.0,
                12.0,
                "middle",
                "",
                &tick_label(t, xs),
            );
        }
        for &t in &yt {
            y_tick_label(&mut out, left, sy(t), &tick_label(t, ys));
        }
        text(
            &mut out,
            (left + right) / 2.0,
            height - 18.0,
            14.0,
            "middle",
            "",
            &self.x_label,
        );
        let (lx, ly) = (22.0, (top + bottom) / 2.0);
        text(
            &mut out,
            lx,
            ly,
            14.0,
            "middle",
            &format!(" transform=\"rotate(-90 {} {})\"", px(lx), px(ly)),
            &self.y_label,
        );
        // Series, clipped to the plot area.
        let _ = writeln!(
            out,
            "<clipPath id=\"plot\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n<g clip-path=\"url(#plot)\" fill=\"none\" stroke-width=\"2\" stroke-linejoin=\"round\">",
            px(left), px(top), px(right - left), px(bottom - top)
        );
        for (i, s) in self.series.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            let finite = |k: usize| s.x[k].is_finite() && s.y[k].is_finite();
            let mut run: Vec<String> = Vec::new();
            let flush = |run: &mut Vec<String>, out: &mut String| {
                if run.len() > 1 {
                    let _ = writeln!(
                        out,
                        "<polyline stroke=\"{colour}\" points=\"{}\"/>",
                        run.join(" ")
                    );
                }
                run.clear();
            };
            for k in 0..s.x.len() {
                if finite(k) {
                    run.push(format!("{},{}", px(sx(s.x[k])), px(sy(s.y[k]))));
                } else {
                    flush(&mut run, &mut out);
                }
            }
            flush(&mut run, &mut out);
            if s.x.len() <= 40 {
                for k in (0..s.x.len()).filter(|&k| finite(k)) {
                    let _ = writeln!(
                        out,
                        "<circle cx=\"{}\" cy=\"{}\" r=\"3\" fill=\"{colour}\" stroke=\"none\"/>",
                        px(sx(s.x[k])),
                        px(sy(s.y[k]))
                    );
                }
            }
        }
        out.push_str("</g>\n");
        // Legend.
        for (i, s) in self.series.iter().enumerate() {
            let y = top + 10.0 + 20.0 * i as f64;
            let colour = PALETTE[i % PALETTE.len()];
            let _ = writeln!(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{colour}\" stroke-width=\"3\"/>", px(right + 14.0), px(y), px(right + 36.0));
            text(&mut out, right + 42.0, y + 4.0, 12.0, "start", "", &s.name);
        }
        out.push_str("</svg>\n");
        Ok(out)
    }

    /// The points as CSV: `series,x,y`, one row per point.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("series,x,y\n");
        for s in &self.series {
            for (x, y) in s.x.iter().zip(&s.y) {
                let _ = writeln!(
                    out,
                    "{},{},{}",
                    super::csv::quote(&s.name),
                    fmt_f64(*x),
                    fmt_f64(*y)
                );
            }
        }
        out
    }

    /// Writes `path` (the SVG) and the CSV beside it; returns the CSV's path.
    pub fn write(&self, path: &Path) -> Result<PathBuf> {
        write_pair(path, &self.to_svg()?, &self.to_csv())
    }
}

fn axis_of(values: impl Iterator<Item = f64>) -> (f64, f64, Vec<f64>, f64) {
    let (lo, hi) = data_range(values);
    axis(lo, hi, 8)
}

fn write_pair(svg_path: &Path, svg: &str, csv: &str) -> Result<PathBuf> {
    let csv_path = svg_path.with_extension("csv");
    if csv_path == svg_path {
        return Err(Error::input(
            "chart file",
            format!("\"{}\"", svg_path.display()),
            "must not end in .csv (the chart's data goes to a .csv beside it)",
        ));
    }
    write_atomic(svg_path, svg.as_bytes())?;
    write_atomic(&csv_path, csv.as_bytes())?;
    Ok(csv_path)
}

impl FieldMap {
    fn check(&self) -> Result<()> {
        if self.points.len() != self.values.len() {
            return Err(Error::Input(format!(
                "colour map '{}': {} points and {} values",
                self.title,
                self.points.len(),
                self.values.len()
            )));
        }
        if self.quads.is_empty() {
            return Err(Error::Input(format!(
                "colour map '{}' has no faces",
                self.title
            )));
        }
        if let Some(n) = self
            .quads
            .iter()
            .flatten()
            .find(|&&n| n >= self.points.len())
        {
            return Err(Error::Input(format!(
                "colour map '{}': node {n} out of range ({} points)",
                self.title,
                self.points.len()
            )));
        }
        if let Some((lo, hi)) = self.range {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(Error::input(
                    &format!("range of colour map '{}'", self.title),
                    format!("[{lo}, {hi}]"),
                    "must be two finite numbers, low < high",
                ));
            }
        }
        Ok(())
    }

    /// The colour range: the fixed one, else that of the drawn nodes' finite values.
    pub fn value_range(&self) -> (f64, f64) {
        self.range
            .unwrap_or_else(|| data_range(self.quads.iter().flatten().map(|&n| self.values[n])))
    }

    /// Colour of a value under the map's range (NaN: grey).
    pub fn colour(&self, v: f64) -> String {
        if !v.is_finite() {
            return NO_VALUE.to_string();
        }
        let (lo, hi) = self.value_range();
        hex(viridis((v - lo) / (hi - lo)))
    }

    /// The map as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        self.check()?;
        let (bx0, bx1) = data_range(self.quads.iter().flatten().map(|&n| self.points[n][0]));
        let (by0, by1) = data_range(self.quads.iter().flatten().map(|&n| self.points[n][1]));
        // Equal scales in x and y, the drawing fitted in a 520 x 520 box.
        let scale = 520.0 / (bx1 - bx0).max(by1 - by0);
        let (pw, ph) = ((bx1 - bx0) * scale, (by1 - by0) * scale);
        // A thin strip is centred beside a colour bar of at least 150 px.
        let (left, bar_top, bar_h) = (70.0, 60.0, ph.max(150.0));
        let top = bar_top + 0.5 * (bar_h - ph);
        let width = left + pw + 150.0;
        let height = bar_top + bar_h + 50.0;
        let sx = |x: f64| left + (x - bx0) * scale;
        let sy = |y: f64| top + (by1 - y) * scale;

        let mut out = String::new();
        svg_open(&mut out, width, height);
        text(
            &mut out,
            width / 2.0,
            30.0,
            17.0,
            "middle",
            " font-weight=\"bold\"",
            &self.title,
        );
        let n = ((MAX_POLYGONS as f64 / self.quads.len() as f64)
            .sqrt()
            .floor() as usize)
            .clamp(1, 8);
        // A stroke of the fill colour closes the hairline seams that anti-aliasing leaves
        // between neighbouring polygons.
        out.push_str("<g stroke-width=\"0.6\" stroke-linejoin=\"round\">\n");
        for q in &self.quads {
            let p = q.map(|k| self.points[k]);
            let v = q.map(|k| self.values[k]);
            let at = |u: f64, w: f64| {
                let s = [(1.0 - u) * (1.0 - w), u * (1.0 - w), u * w, (1.0 - u) * w];
                let x = (0..4).map(|i| s[i] * p[i][0]).sum::<f64>();
                let y = (0..4).map(|i| s[i] * p[i][1]).sum::<f64>();
                (x, y, (0..4).map(|i| s[i] * v[i]).sum::<f64>())
            };
            for i in 0..n {
                for j in 0..n {
                    let (u0, u1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                    let (w0, w1) = (j as f64 / n as f64, (j + 1) as f64 / n as f64);
                    let corners = [at(u0, w0), at(u1, w0), at(u1, w1), at(u0, w1)];
                    let colour = self.colour(at(0.5 * (u0 + u1), 0.5 * (w0 + w1)).2);
                    let pts: Vec<String> = corners
                        .iter()
                        .map(|c| format!("{},{}", px(sx(c.0)), px(sy(c.1))))
                        .collect();
                    let _ = writeln!(
                        out,
                        "<polygon points=\"{}\" fill=\"{colour}\" stroke=\"{colour}\"/>",
                        pts.join(" ")
                    );
                }
            }
        }
        out.push_str("</g>\n");
        // Face outlines, thin, to show the mesh.
        out.push_str(
            "<g fill=\"none\" stroke=\"#ffffff\" stroke-opacity=\"0.25\" stroke-width=\"0.5\">\n",
        );
        for q in &self.quads {
            let pts: Vec<String> = q
                .iter()
                .map(|&k| {
                    format!(
                        "{},{}",
                        px(sx(self.points[k][0])),
                        px(sy(self.points[k][1]))
                    )
                })
                .collect();
            let _ = writeln!(out, "<polygon points=\"{}\"/>", pts.join(" "));
        }
        out.push_str("</g>\n");
        // Coordinate ticks below and left of the drawing.
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\" stroke-width=\"0.8\"/>",
            px(left), px(top), px(pw), px(ph)
        );
        let (xt, xs) = nice_ticks(bx0, bx1, ((pw / 60.0) as usize).clamp(1, 6));
        for t in xt {
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#333\"/>",
                px(sx(t)),
                px(top + ph),
                px(top + ph + 5.0)
            );
            text(
                &mut out,
                sx(t),
                top + ph + 19.0,
                12.0,
                "middle",
                "",
                &tick_label(t, xs),
            );
        }
        let (yt, ys) = nice_ticks(by0, by1, ((ph / 40.0) as usize).clamp(1, 6));
        for t in yt {
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#333\"/>",
                px(left - 5.0),
                px(sy(t)),
                px(left)
            );
            y_tick_label(&mut out, left, sy(t), &tick_label(t, ys));
        }
        text(
            &mut out,
            left + pw / 2.0,
            top + ph + 38.0,
            13.0,
            "middle",
            "",
            "x",
        );
        text(
            &mut out,
            left - 45.0,
            top + ph / 2.0,
            13.0,
            "middle",
            "",
            "y",
        );
        self.colour_bar(&mut out, left + pw + 30.0, bar_top, bar_h);
        out.push_str("</svg>\n");
        Ok(out)
    }

    /// Vertical colour bar at (x, top), `h` high, low values at the bottom, with ticks.
    fn colour_bar(&self, out: &mut String, x: f64, top: f64, h: f64) {
        let (lo, hi) = self.value_range();
        let w = 18.0;
        out.push_str("<defs><linearGradient id=\"bar\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">\n");
        for (i, c) in VIRIDIS.iter().enumerate() {
            let _ = writeln!(
                out,
                "<stop offset=\"{}\" stop-color=\"{}\"/>",
                fmt_f64(i as f64 / (VIRIDIS.len() - 1) as f64),
                hex(*c)
            );
        }
        out.push_str("</linearGradient></defs>\n");
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{w}\" height=\"{}\" fill=\"url(#bar)\" stroke=\"#333\" stroke-width=\"0.8\"/>",
            px(x), px(top), px(h)
        );
        let (ticks, step) = nice_ticks(lo, hi, 6);
        for t in ticks {
            let y = top + (hi - t) / (hi - lo) * h;
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#333\" stroke-width=\"1\"/>",
                px(x + w), px(y), px(x + w + 5.0)
            );
            text(
                out,
                x + w + 8.0,
                y + 4.0,
                12.0,
                "start",
                " class=\"tick\"",
                &tick_label(t, step),
            );
        }
        text(
            out,
            x + w / 2.0,
            top - 10.0,
            12.0,
            "middle",
            "",
            &self.label,
        );
    }

    /// The drawn nodes as CSV: `node,x,y,value`, each node once, in index order.
    pub fn to_csv(&self) -> String {
        let mut used = vec![false; self.points.len()];
        for &k in self.quads.iter().flatten() {
            used[k] = true;
        }
        let mut out = String::from("node,x,y,value\n");
        for (k, _) in used.iter().enumerate().filter(|(_, u)| **u) {
            let [x, y] = self.points[k];
            let _ = writeln!(
                out,
                "{k},{},{},{}",
                fmt_f64(x),
                fmt_f64(y),
                fmt_f64(self.values[k])
            );
        }
        out
    }

    /// Writes `path` (the SVG) and the CSV beside it; returns the CSV's path.
    pub fn write(&self, path: &Path) -> Result<PathBuf> {
        write_pair(path, &self.to_svg()?, &self.to_csv())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    /// Well-formedness without an XML parser: every opened element is closed in order,
    /// attribute quotes balance, and no number printed as NaN or inf.
    pub(crate) fn assert_well_formed(svg: &str) {
        assert!(svg.starts_with("<?xml"), "XML declaration");
        let mut stack: Vec<String> = Vec::new();
        let mut rest = svg;
        while let Some(open) = rest.find('<') {
            let close = rest[open..].find('>').expect("tag closed") + open;
            let tag = &rest[open + 1..close];
            assert_eq!(tag.matches('"').count() % 2, 0, "quotes in <{tag}>");
            assert!(!tag.contains('<'), "nested '<' in <{tag}>");
            if tag.starts_with('?') {
            } else if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(
                    stack.pop().as_deref(),
                    Some(name.trim()),
                    "closing </{name}>"
                );
            } else if !tag.ends_with('/') {
                let name = tag.split_whitespace().next().expect("element name");
                stack.push(name.to_string());
            }
            // Text between tags must not hold a raw '&' that is not an entity.
            let text_end = rest[close..].find('<').map_or(rest.len(), |i| i + close);
            let between = &rest[close + 1..text_end];
            for (i, _) in between.match_indices('&') {
                assert!(
                    ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
                        .iter()
                        .any(|e| between[i..].starts_with(e)),
                    "raw & in text {between}"
                );
            }
            rest = &rest[close + 1..];
        }
        assert!(stack.is_empty(), "unclosed elements {stack:?}");
        assert_eq!(svg.matches("<svg").count(), 1);
        for bad in ["NaN", "inf"] {
            assert!(!svg.contains(bad), "{bad} printed in the SVG");
        }
    }

    fn chart() -> LineChart {
        LineChart {
            title: "Punch force <full cup> & travel".into(),
            x_label: "punch travel [mm]".into(),
            y_label: "force [kN]".into(),
            series: vec![
                Series {
                    name: "paper, 25 x 25".into(),
                    x: vec![0.0, 5.0, 10.0, 15.0],
                    y: vec![0.0, 30.0, 42.0, 45.5],
                },
                Series {
                    name: "benchmark".into(),
                    x: vec![0.0, 5.0, f64::NAN, 15.0, 20.0],
                    y: vec![0.0, 25.0, 1.0, 44.0, 47.0],
                },
            ],
        }
    }

    #[test]
    fn nice_ticks_are_round_and_cover_the_range() {
        let (t, step) = nice_ticks(0.0, 4900.0, 8);
        assert_eq!(step, 1000.0);
        assert_eq!(t, vec![0.0, 1000.0, 2000.0, 3000.0, 4000.0]);
        let (t, step) = nice_ticks(0.01, 0.16, 6);
        assert_eq!(step, 0.05);
        assert_eq!(t.len(), 3);
        assert!((t[0] - 0.05).abs() < 1e-15 && (t[2] - 0.15).abs() < 1e-15);
        let (t, _) = nice_ticks(-3.0, 3.0, 6);
        assert_eq!(t, vec![-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0]);
        assert!(t.iter().all(|v| !(v.is_sign_negative() && *v == 0.0)));
        // Labels: decimals follow the step; no "-0".
        assert_eq!(tick_label(0.1 + 0.2, 0.1), "0.3");
        assert_eq!(tick_label(-1e-17, 0.05), "0.00");
        assert_eq!(tick_label(2000.0, 1000.0), "2000");
        assert_eq!(tick_label(2.5e-6, 5e-7), "2.5e-6");
        // Degenerate ranges still give one tick, no panic.
        assert_eq!(nice_ticks(1.0, 1.0, 5).0, vec![1.0]);
    }

    #[test]
    fn viridis_hits_its_anchors_and_clamps() {
        assert_eq!(hex(viridis(0.0)), "#440154");
        assert_eq!(hex(viridis(0.5)), "#21908c");
        assert_eq!(hex(viridis(1.0)), "#fde725");
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        // Half-way between anchors 0 and 1: the mean colour, rounded.
        assert_eq!(viridis(1.0 / 16.0), [0x46, 0x17, 0x68]);
        // Viridis grows monotonically in lightness: the green channel never falls.
        let g: Vec<u8> = (0..=100).map(|i| viridis(i as f64 / 100.0)[1]).collect();
        assert!(g.windows(2).all(|w| w[1] >= w[0]));
    }

    #[test]
    fn line_chart_is_well_formed_with_title_legend_and_csv() {
        let c = chart();
        let svg = c.to_svg().unwrap();
        assert_well_formed(&svg);
        assert!(svg.contains("Punch force &lt;full cup&gt; &amp; travel"));
        assert!(svg.contains(">paper, 25 x 25</text>") && svg.contains(">benchmark</text>"));
        assert!(svg.contains(">punch travel [mm]</text>"));
        // The NaN splits the second series: one polyline before it (2 points), one after.
        assert_eq!(svg.matches("<polyline").count(), 3);
        // y ticks 0..50 by 10 (data 0..47).
        for label in ["0", "10", "20", "30", "40", "50"] {
            assert!(svg.contains(&format!(">{label}</text>")), "y tick {label}");
        }
        let dir = temp_dir("svg-line");
        let csv = c.write(&dir.join("force.svg")).unwrap();
        assert_eq!(csv, dir.join("force.csv"));
        let text = std::fs::read_to_string(&csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "series,x,y");
        assert_eq!(lines.len(), 1 + 4 + 5);
        assert_eq!(lines[1], "\"paper, 25 x 25\",0,0");
        assert_eq!(lines[8], "benchmark,15,44");
        assert_eq!(std::fs::read_to_string(dir.join("force.svg")).unwrap(), svg);
        assert!(
            c.write(&dir.join("data.csv")).is_err(),
            "a .csv chart name is refused"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bad_line_charts_are_errors_naming_the_series() {
        let mut c = chart();
        c.series[1].y.pop();
        let err = c.to_svg().unwrap_err().to_string();
        assert!(
            err.contains("'benchmark'") && err.contains("5 x values and 4 y values"),
            "{err}"
        );
        c.series.clear();
        assert!(c.to_svg().unwrap_err().to_string().contains("no series"));
    }

    /// A 2 x 1 strip of faces with values 0..3 on its nodes.
    fn strip(range: Option<(f64, f64)>) -> FieldMap {
        FieldMap {
            title: "frictional work".into(),
            label: "work [N mm]".into(),
            points: vec![
                [0.0, 0.0],
                [1.0, 0.0],
                [2.0, 0.0],
                [0.0, 1.0],
                [1.0, 1.0],
                [2.0, 1.0],
            ],
            values: vec![0.0, 1.0, 2.0, 1.0, 2.0, 3.0],
            quads: vec![[0, 1, 4, 3], [1, 2, 5, 4]],
            range,
        }
    }

    fn tick_labels(svg: &str) -> Vec<f64> {
        svg.match_indices("class=\"tick\">")
            .map(|(i, m)| {
                let s = &svg[i + m.len()..];
                s[..s.find('<').unwrap()].parse().unwrap()
            })
            .collect()
    }

    #[test]
    fn colour_map_maps_values_to_viridis_over_its_range() {
        let m = strip(None);
        assert_eq!(m.value_range(), (0.0, 3.0));
        assert_eq!(m.colour(0.0), "#440154");
        assert_eq!(m.colour(1.5), "#21908c");
        assert_eq!(m.colour(3.0), "#fde725");
        assert_eq!(m.colour(f64::NAN), NO_VALUE);
        let fixed = strip(Some((0.0, 6.0)));
        assert_eq!(fixed.colour(3.0), "#21908c");
        assert_eq!(fixed.colour(100.0), "#fde725", "clamped above the range");
        let svg = m.to_svg().unwrap();
        assert_well_formed(&svg);
        // 8 x 8 sub-quads per face (few faces); the first sub-quad of face 0 has the
        // bilinear value u + w = 1/16 + 1/16 at its centre.
        assert_eq!(svg.matches("<polygon points").count(), 2 * 64 + 2);
        assert!(svg.contains(&format!("fill=\"{}\"", m.colour(0.125))));
        // Colour bar: nice ticks over the range, at the right heights.
        assert_eq!(tick_labels(&svg), vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]);
        assert_eq!(
            tick_labels(&fixed.to_svg().unwrap()),
            vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        );
        assert_eq!(svg.matches("<stop ").count(), 9);
        assert!(svg.contains(">work [N mm]</text>"));
    }

    #[test]
    fn colour_map_csv_and_input_errors() {
        let dir = temp_dir("svg-map");
        let mut m = strip(None);
        m.points.push([9.0, 9.0]);
        m.values.push(f64::NAN); // not on a face: not drawn, not listed
        let csv = m
            .write(&dir.join("maps/work.svg"))
            .map(|p| std::fs::read_to_string(p).unwrap());
        assert!(
            csv.is_err(),
            "the folder must exist: an I/O error, not a panic"
        );
        std::fs::create_dir_all(dir.join("maps")).unwrap();
        let csv = std::fs::read_to_string(m.write(&dir.join("maps/work.svg")).unwrap()).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 1 + 6);
        assert_eq!(lines[0], "node,x,y,value");
        assert_eq!(lines[6], "5,2,1,3");
        let _ = std::fs::remove_dir_all(&dir);

        let mut bad = strip(Some((1.0, 1.0)));
        assert!(bad.to_svg().unwrap_err().to_string().contains("low < high"));
        bad.range = None;
        bad.quads.push([0, 1, 2, 99]);
        assert!(bad
            .to_svg()
            .unwrap_err()
            .to_string()
            .contains("node 99 out of range"));
        bad.quads.clear();
        assert!(bad.to_svg().unwrap_err().to_string().contains("no faces"));
    }
}
