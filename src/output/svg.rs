//! Standalone SVG charts, shared parts: the viridis colour map, "nice" axis ticks and their
//! labels, text elements, and writing a chart with a CSV of its data beside it
//! (`name.svg` and `name.csv`) so that the numbers behind a picture can be re-plotted.
//! The charts themselves: [`LineChart`] (x-y series) and [`FieldMap`] (a top view colour
//! map of a nodal field on quadrilateral faces).
//!
//! Axis ticks are "nice" numbers: the step is 1, 2 or 5 times a power of ten, the smallest
//! such step giving at most the requested number of intervals over the data range.
//!
//! Colour map: viridis (perceptually uniform, readable in grey and by colour-blind readers),
//! from the nine anchors of `viridisLite::viridis(9)` with linear interpolation in sRGB
//! between them.

pub use super::field_map::FieldMap;
pub use super::line_chart::{LineChart, Series};

use super::{write_atomic, xml_escape};
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Nine anchors of viridis, evenly spaced in [0, 1] (viridisLite::viridis(9)).
pub(crate) const VIRIDIS: [[u8; 3]; 9] = [
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
pub(crate) const NO_VALUE: &str = "#bdbdbd";

/// The viridis colour of `t` in [0, 1] (clamped; NaN gives the low end).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (VIRIDIS.len() - 1) as f64;
    let i = (s.floor() as usize).min(VIRIDIS.len() - 2);
    let f = s - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [0, 1, 2].map(|k| (a[k] as f64 + f * (b[k] as f64 - a[k] as f64)).round() as u8)
}

pub(crate) fn hex([r, g, b]: [u8; 3]) -> String {
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
pub(crate) fn data_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
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
pub(crate) fn axis(lo: f64, hi: f64, max_intervals: usize) -> (f64, f64, Vec<f64>, f64) {
    let (_, step) = nice_ticks(lo, hi, max_intervals);
    let (a, b) = ((lo / step).floor() * step, (hi / step).ceil() * step);
    let (ticks, step) = nice_ticks(a, b, max_intervals);
    (a, b, ticks, step)
}

/// `x` in 2 decimals (enough for a pixel grid), never "-0.00".
pub(crate) fn px(x: f64) -> String {
    let s = format!("{x:.2}");
    if s == "-0.00" {
        "0.00".into()
    } else {
        s
    }
}

pub(crate) fn svg_open(out: &mut String, width: f64, height: f64) {
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
pub(crate) fn y_tick_label(out: &mut String, x_axis: f64, y: f64, label: &str) {
    text(out, x_axis - 8.0, y + 4.0, 12.0, "end", "", label);
}

/// The plot area of an x-y chart: its pixel box and the data ranges it maps, so that a
/// chart draws its grid, frame, tick labels and axis titles the same way as every other.
pub(crate) struct PlotFrame {
    pub left: f64,
    pub right: f64,
    pub top: f64,
    pub bottom: f64,
    /// Data ranges (x0, x1) and (y0, y1) mapped onto [left, right] and [bottom, top].
    pub x: (f64, f64),
    pub y: (f64, f64),
}

impl PlotFrame {
    pub fn sx(&self, x: f64) -> f64 {
        self.left + (x - self.x.0) / (self.x.1 - self.x.0) * (self.right - self.left)
    }

    pub fn sy(&self, y: f64) -> f64 {
        self.bottom - (y - self.y.0) / (self.y.1 - self.y.0) * (self.bottom - self.top)
    }

    /// Grid lines at the ticks, the frame, tick labels (steps `xs`, `ys`) and the axis
    /// titles (x below, y rotated at the left edge); `height` is the SVG's.
    #[allow(clippy::too_many_arguments)]
    pub fn draw_axes(
        &self,
        out: &mut String,
        (xt, xs): (&[f64], f64),
        (yt, ys): (&[f64], f64),
        height: f64,
        x_label: &str,
        y_label: &str,
    ) {
        let (left, right, top, bottom) = (self.left, self.right, self.top, self.bottom);
        out.push_str("<g stroke=\"#e0e0e0\" stroke-width=\"1\">\n");
        for &t in xt {
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\"/>",
                px(self.sx(t)),
                px(top),
                px(bottom)
            );
        }
        for &t in yt {
            let _ = writeln!(
                out,
                "<line x1=\"{1}\" y1=\"{0}\" x2=\"{2}\" y2=\"{0}\"/>",
                px(self.sy(t)),
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
        for &t in xt {
            text(
                out,
                self.sx(t),
                bottom + 18.0,
                12.0,
                "middle",
                "",
                &tick_label(t, xs),
            );
        }
        for &t in yt {
            y_tick_label(out, left, self.sy(t), &tick_label(t, ys));
        }
        text(
            out,
            (left + right) / 2.0,
            height - 18.0,
            14.0,
            "middle",
            "",
            x_label,
        );
        let (lx, ly) = (22.0, (top + bottom) / 2.0);
        let rotate = format!(" transform=\"rotate(-90 {} {})\"", px(lx), px(ly));
        text(out, lx, ly, 14.0, "middle", &rotate, y_label);
    }

    /// Opens a group clipped to the plot area (`attributes`: further attributes of the
    /// group, each with a leading space); the caller closes it with `</g>`.
    pub fn open_clipped(&self, out: &mut String, attributes: &str) {
        let _ = writeln!(
            out,
            "<clipPath id=\"plot\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n<g clip-path=\"url(#plot)\"{attributes}>",
            px(self.left), px(self.top), px(self.right - self.left), px(self.bottom - self.top)
        );
    }
}

pub(crate) fn write_pair(svg_path: &Path, svg: &str, csv: &str) -> Result<PathBuf> {
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

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
}
