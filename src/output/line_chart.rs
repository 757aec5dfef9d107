//! A line chart of x-y series as a standalone SVG, with its points as CSV beside it.

use super::fmt_f64;
use super::svg::{axis, data_range, px, svg_open, text, write_pair, PlotFrame, PALETTE};
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
            28.0,
            17.0,
            "middle",
            " font-weight=\"bold\"",
            &self.title,
        );
        frame.draw_axes(
            &mut out,
            (&xt, xs),
            (&yt, ys),
            height,
            &self.x_label,
            &self.y_label,
        );
        // Series, clipped to the plot area.
        frame.open_clipped(
            &mut out,
            " fill=\"none\" stroke-width=\"2\" stroke-linejoin=\"round\"",
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::svg::tests::assert_well_formed;
    use crate::output::test_util::temp_dir;

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
}
