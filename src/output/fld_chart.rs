//! The forming limit diagram (FLD) of a committed state as a standalone SVG, with its points
//! as CSV beside it.
//!
//! Every sheet column is one point (minor strain across, major strain up, both in percent
//! of true strain, `100 ε`), coloured by its formability zone (formability/flc.rs); the
//! forming limit curve is drawn solid and the safety-margin line (the curve lowered by
//! `flc_safety_margin`) dashed, both sampled at 201 minor strains across the axis. The
//! axes span the points and the curve's plane-strain intercept, so the curve is always in
//! view. Size: one short `<circle>` per column (~60 bytes), ~160 kB for 2600 columns.

use super::fmt_f64;
use super::formability::{Flc, Formability, Zone};
use super::svg::{axis, data_range, px, svg_open, text, write_pair, PlotFrame};
use crate::Result;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The FLD's content: the points, the curve and margin, the title and a subtitle (the
/// material's description).
pub struct FldChart<'a> {
    pub title: String,
    pub subtitle: String,
    pub formability: &'a Formability,
    pub safety_margin: f64,
}

impl FldChart<'_> {
    fn curve_points(flc: &Flc, lo: f64, hi: f64, shift: f64) -> Vec<(f64, f64)> {
        (0..=200)
            .map(|i| {
                let e2 = lo + (hi - lo) * i as f64 / 200.0;
                (e2, flc.major_limit(e2) - shift)
            })
            .collect()
    }

    /// The chart as an SVG document.
    ///
    /// A subtitle longer than [`SUBTITLE_CHARS`] is broken at its commas (a material's
    /// description lists its constants so), so that it stays within the picture.
    pub fn to_svg(&self) -> String {
        let f = self.formability;
        let (minor, major) = (&f.columns.minor, &f.columns.major);
        let pct = |v: f64| 100.0 * v;
        let (mut x_lo, mut x_hi) = data_range(minor.iter().map(|&v| pct(v)));
        let (mut y_lo, mut y_hi) = data_range(major.iter().map(|&v| pct(v)));
        // A margin of 5 % of the span around the points, so none sits on the frame.
        let (dx, dy) = (0.05 * (x_hi - x_lo), 0.05 * (y_hi - y_lo));
        x_lo = (x_lo - dx).min(-10.0);
        x_hi = (x_hi + dx).max(10.0);
        y_lo = (y_lo - dy).min(0.0);
        y_hi += dy;
        if let Ok(flc) = &f.flc {
            y_hi = y_hi.max(pct(flc.major_limit(0.0)) * 1.2);
        }
        let (x0, x1, xt, xs) = axis(x_lo, x_hi, 8);
        let (y0, y1, yt, ys) = axis(y_lo, y_hi, 8);
        let (width, height) = (760.0, 560.0);
        let subtitle = wrap_at_commas(&self.subtitle, SUBTITLE_CHARS);
        let top = 49.0 + 13.0 * subtitle.len() as f64;
        let (left, right, bottom) = (80.0, width - 200.0, height - 60.0);
        let frame = PlotFrame {
            left,
            right,
            top,
            bottom,
            x: (x0, x1),
            y: (y0, y1),
        };
        let (sx, sy) = (|x: f64| frame.sx(x), |y: f64| frame.sy(y));
        let mut out = String::new();
        svg_open(&mut out, width, height);
        text(
            &mut out,
            (left + right) / 2.0,
            26.0,
            17.0,
            "middle",
            " font-weight=\"bold\"",
            &self.title,
        );
        for (k, line) in subtitle.iter().enumerate() {
            text(
                &mut out,
                (left + right) / 2.0,
                44.0 + 13.0 * k as f64,
                11.0,
                "middle",
                "",
                line,
            );
        }
        frame.draw_axes(
            &mut out,
            (&xt, xs),
            (&yt, ys),
            height,
            "minor strain [%]",
            "major strain [%]",
        );
        frame.open_clipped(&mut out, "");
        for (k, z) in f.zone.iter().enumerate() {
            let _ = writeln!(
                out,
                "<circle cx=\"{}\" cy=\"{}\" r=\"2\" fill=\"{}\"/>",
                px(sx(pct(minor[k]))),
                px(sy(pct(major[k]))),
                z.colour()
            );
        }
        if let Ok(flc) = &f.flc {
            for (shift, dash) in [(0.0, ""), (self.safety_margin, " stroke-dasharray=\"6 4\"")] {
                let pts: Vec<String> = Self::curve_points(flc, x0 / 100.0, x1 / 100.0, shift)
                    .iter()
                    .map(|&(a, b)| format!("{},{}", px(sx(pct(a))), px(sy(pct(b)))))
                    .collect();
                let _ = writeln!(
                    out,
                    "<polyline fill=\"none\" stroke=\"#000\" stroke-width=\"2\"{dash} points=\"{}\"/>",
                    pts.join(" ")
                );
            }
        }
        out.push_str("</g>\n");
        let legend: Vec<(String, &str, bool)> = (Zone::ALL.iter().rev())
            .map(|z| {
                let n = f.zone.iter().filter(|&&q| q == *z).count();
                (
                    format!("{} ({n})", z.name().replace('_', " ")),
                    z.colour(),
                    false,
                )
            })
            .chain(f.flc.iter().flat_map(|_| {
                [
                    ("forming limit curve".to_string(), "#000", true),
                    (
                        format!("FLC - {}", fmt_f64(self.safety_margin)),
                        "#000",
                        true,
                    ),
                ]
            }))
            .collect();
        for (i, (name, colour, line)) in legend.iter().enumerate() {
            let y = top + 10.0 + 20.0 * i as f64;
            if *line {
                let dash = if i + 1 == legend.len() {
                    " stroke-dasharray=\"6 4\""
                } else {
                    ""
                };
                let _ = writeln!(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{colour}\" stroke-width=\"2\"{dash}/>", px(right + 14.0), px(y), px(right + 36.0));
            } else {
                let _ = writeln!(
                    out,
                    "<circle cx=\"{}\" cy=\"{}\" r=\"5\" fill=\"{colour}\"/>",
                    px(right + 25.0),
                    px(y)
                );
            }
            text(&mut out, right + 42.0, y + 4.0, 12.0, "start", "", name);
        }
        out.push_str("</svg>\n");
        out
    }

    /// The points as CSV: `column,minor_strain,major_strain,thinning_pct,flc_margin,zone`.
    pub fn to_csv(&self) -> String {
        let f = self.formability;
        let mut out =
            String::from("column,minor_strain,major_strain,thinning_pct,flc_margin,zone\n");
        for k in 0..f.zone.len() {
            let _ = writeln!(
                out,
                "{k},{},{},{},{},{}",
                fmt_f64(f.columns.minor[k]),
                fmt_f64(f.columns.major[k]),
                fmt_f64(f.thinning(k)),
                if f.margin[k].is_finite() {
                    fmt_f64(f.margin[k])
                } else {
                    String::new()
                },
                f.zone[k].name()
            );
        }
        out
    }

    /// Writes `path` (the SVG) and the CSV beside it; returns the CSV's path.
    pub fn write(&self, path: &Path) -> Result<PathBuf> {
        write_pair(path, &self.to_svg(), &self.to_csv())
    }
}

/// Characters of 11-pixel text that fit the FLD's width centred over its plot.
const SUBTITLE_CHARS: usize = 100;

/// `text` in lines of at most `width` characters, broken after commas (a part longer than
/// `width` stays whole on its line).
fn wrap_at_commas(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for part in text.split_inclusive(", ") {
        match lines.last_mut() {
            Some(line) if line.chars().count() + part.trim_end().chars().count() <= width => {
                line.push_str(part)
            }
            _ => lines.push(part.to_string()),
        }
    }
    lines.iter().map(|l| l.trim_end().to_string()).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn long_subtitles_break_at_commas_within_the_width() {
        let text = "elastoplastic E=71000 nu=0.33, Hill48 F=0.5 G=0.5 H=0.5 L=1.5 M=1.5 N=1.5, \
                    Swift C=576 eps0=0.01658 n=0.36";
        let lines = super::wrap_at_commas(text, 60);
        assert_eq!(lines.len(), 3, "{lines:?}");
        assert!(lines.iter().all(|l| l.chars().count() <= 60), "{lines:?}");
        assert_eq!(lines.join(" "), text);
        assert_eq!(super::wrap_at_commas("short", 60), vec!["short"]);
    }

    use super::*;
    use crate::output::formability::{ColumnStrains, Thresholds};
    use crate::output::svg::tests::assert_well_formed;

    #[test]
    fn fld_is_well_formed_with_curve_points_and_csv() {
        let columns = ColumnStrains {
            major: vec![0.05, 0.2, 0.4],
            minor: vec![-0.02, 0.0, 0.1],
            thickness: vec![0.8, 0.7, 0.5],
            initial_thickness: vec![0.8, 0.8, 0.8],
        };
        let flc = Flc::keeler_brazier(0.2, 0.8).unwrap();
        let margin: Vec<f64> = (0..3)
            .map(|k| flc.margin(columns.major[k], columns.minor[k]))
            .collect();
        let t = Thresholds::default();
        let zone = (0..3)
            .map(|k| {
                let p = crate::output::formability::SheetPoint {
                    major: columns.major[k],
                    minor: columns.minor[k],
                    thickness_strain: (columns.thickness[k] / 0.8).ln(),
                    thinning_pct: 100.0 * (1.0 - columns.thickness[k] / 0.8),
                };
                crate::output::formability::zone(&p, Some(margin[k]), &t)
            })
            .collect();
        let f = Formability {
            flc: Ok(flc),
            columns,
            margin,
            zone,
        };
        let chart = FldChart {
            title: "DC04 <steel>".into(),
            subtitle: "Swift n = 0.2".into(),
            formability: &f,
            safety_margin: 0.1,
        };
        let svg = chart.to_svg();
        assert_well_formed(&svg);
        assert_eq!(
            svg.matches("<circle").count(),
            3 + 7,
            "3 points and 7 legend markers"
        );
        assert_eq!(svg.matches("<polyline").count(), 2, "curve and margin line");
        assert!(svg.contains("DC04 &lt;steel&gt;"));
        assert!(
            svg.contains(">crack (1)</text>"),
            "the 40 % major strain point is beyond the curve"
        );
        let csv = chart.to_csv();
        assert_eq!(csv.lines().count(), 4);
        assert!(csv.lines().nth(3).unwrap().ends_with(",crack"));
    }
}
