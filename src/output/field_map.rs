//! A top view colour map of a nodal field on quadrilateral faces as a standalone SVG, with
//! the drawn nodes as CSV beside it.

use super::fmt_f64;
use super::svg::{
    data_range, hex, nice_ticks, px, svg_open, text, tick_label, viridis, write_pair, y_tick_label,
    NO_VALUE, VIRIDIS,
};
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Sub-quads per chart: each costs about 40 bytes of path data, so the file stays near or
/// below 150 kB whatever the mesh (a 25 x 25 face set is drawn 2 x 2 per face).
const MAX_SUBQUADS: usize = 3_000;
/// Colours are quantised to steps of 1/64 of the range: one `<path>` per colour holds every
/// sub-quad of that colour (64 steps are finer than the eye separates on viridis).
const COLOUR_STEPS: f64 = 64.0;

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
    /// Axis titles ("x [mm]"); empty gives "x" and "y".
    pub x_label: String,
    pub y_label: String,
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

    /// Colour of a value under the map's range (NaN: grey), quantised to
    /// [`COLOUR_STEPS`] steps of the range.
    pub fn colour(&self, v: f64) -> String {
        if !v.is_finite() {
            return NO_VALUE.to_string();
        }
        let (lo, hi) = self.value_range();
        let t = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
        hex(viridis((t * COLOUR_STEPS).round() / COLOUR_STEPS))
    }

    /// The map as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        self.check()?;
        let frame = self.frame();
        let mut out = String::new();
        svg_open(&mut out, frame.width, frame.height);
        text(
            &mut out,
            frame.width / 2.0,
            30.0,
            17.0,
            "middle",
            " font-weight=\"bold\"",
            &self.title,
        );
        self.colour_fill(&mut out, &frame);
        self.face_outlines(&mut out, &frame);
        Self::coordinate_ticks(&mut out, &frame);
        self.axis_titles(&mut out, &frame);
        self.colour_bar(
            &mut out,
            frame.left + frame.pw + 30.0,
            frame.bar_top,
            frame.bar_h,
        );
        out.push_str("</svg>\n");
        Ok(out)
    }

    /// The page layout: the drawn nodes' bounding box drawn at equal scales in x and y,
    /// fitted in a 520 x 520 box, 70 px from the left; a thin strip is centred vertically
    /// beside a colour bar of at least 150 px; room for the ticks, titles and bar around.
    fn frame(&self) -> Frame {
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
        Frame {
            bx0,
            bx1,
            by0,
            by1,
            scale,
            pw,
            ph,
            left,
            top,
            bar_top,
            bar_h,
            width,
            height,
        }
    }

    /// The colour fill: each face cut into `n x n` sub-quads (`n` from [`MAX_SUBQUADS`],
    /// 1 to 8), each coloured by the field interpolated bilinearly at its centre, its
    /// corners placed by the same bilinear map (shape functions `(1-u)(1-w)`, `u(1-w)`,
    /// `uw`, `(1-u)w`). Sub-quads are grouped by colour, one path each; a stroke of the fill
    /// colour closes the hairline seams that anti-aliasing leaves between neighbouring
    /// polygons.
    fn colour_fill(&self, out: &mut String, frame: &Frame) {
        let n = ((MAX_SUBQUADS as f64 / self.quads.len() as f64)
            .sqrt()
            .floor() as usize)
            .clamp(1, 8);
        let mut by_colour: std::collections::BTreeMap<String, String> = Default::default();
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
                    let d = by_colour.entry(colour).or_default();
                    for (k, c) in corners.iter().enumerate() {
                        let _ = write!(
                            d,
                            "{}{} {}",
                            if k == 0 { "M" } else { "L" },
                            short(frame.sx(c.0)),
                            short(frame.sy(c.1))
                        );
                    }
                    d.push('Z');
                }
            }
        }
        out.push_str("<g stroke-width=\"0.6\" stroke-linejoin=\"round\">\n");
        for (colour, d) in &by_colour {
            let _ = writeln!(
                out,
                "<path fill=\"{colour}\" stroke=\"{colour}\" d=\"{d}\"/>"
            );
        }
        out.push_str("</g>\n");
    }

    /// Face outlines, thin and translucent white, to show the mesh: one path.
    fn face_outlines(&self, out: &mut String, frame: &Frame) {
        let mut d = String::new();
        for q in &self.quads {
            for (k, &node) in q.iter().enumerate() {
                let [x, y] = self.points[node];
                let _ = write!(
                    d,
                    "{}{} {}",
                    if k == 0 { "M" } else { "L" },
                    short(frame.sx(x)),
                    short(frame.sy(y))
                );
            }
            d.push('Z');
        }
        let _ = writeln!(
            out,
            "<path fill=\"none\" stroke=\"#ffffff\" stroke-opacity=\"0.25\" stroke-width=\"0.5\" d=\"{d}\"/>"
        );
    }

    /// The drawing's border and its coordinate ticks, below (at most one per 60 px) and
    /// left of it (one per 40 px), 1 to 6 each.
    fn coordinate_ticks(out: &mut String, frame: &Frame) {
        let (left, top, pw, ph) = (frame.left, frame.top, frame.pw, frame.ph);
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\" stroke-width=\"0.8\"/>",
            px(left), px(top), px(pw), px(ph)
        );
        let (xt, xs) = nice_ticks(frame.bx0, frame.bx1, ((pw / 60.0) as usize).clamp(1, 6));
        for t in xt {
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#333\"/>",
                px(frame.sx(t)),
                px(top + ph),
                px(top + ph + 5.0)
            );
            text(
                out,
                frame.sx(t),
                top + ph + 19.0,
                12.0,
                "middle",
                "",
                &tick_label(t, xs),
            );
        }
        let (yt, ys) = nice_ticks(frame.by0, frame.by1, ((ph / 40.0) as usize).clamp(1, 6));
        for t in yt {
            let _ = writeln!(
                out,
                "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#333\"/>",
                px(left - 5.0),
                px(frame.sy(t)),
                px(left)
            );
            y_tick_label(out, left, frame.sy(t), &tick_label(t, ys));
        }
    }

    /// The axis titles below and (rotated) left of the drawing: the map's own, or "x" and
    /// "y".
    fn axis_titles(&self, out: &mut String, frame: &Frame) {
        let (left, top, pw, ph) = (frame.left, frame.top, frame.pw, frame.ph);
        text(
            out,
            left + pw / 2.0,
            top + ph + 38.0,
            13.0,
            "middle",
            "",
            if self.x_label.is_empty() {
                "x"
            } else {
                &self.x_label
            },
        );
        text(
            out,
            left - 45.0,
            top + ph / 2.0,
            13.0,
            "middle",
            &format!(
                " transform=\"rotate(-90 {} {})\"",
                px(left - 45.0),
                px(top + ph / 2.0)
            ),
            if self.y_label.is_empty() {
                "y"
            } else {
                &self.y_label
            },
        );
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
        let (nice, step) = nice_ticks(lo, hi, 6);
        // The ends of the range are always ticked (with the digits they need); a nice tick
        // closer than 40 % of a step to an end would overlap its label and is left out.
        let mut ticks: Vec<(f64, String)> = vec![(lo, end_label(lo, step))];
        ticks.extend(
            (nice.into_iter())
                .filter(|t| (t - lo).abs() > 0.4 * step && (hi - t).abs() > 0.4 * step)
                .map(|t| (t, tick_label(t, step))),
        );
        ticks.push((hi, end_label(hi, step)));
        for (t, label) in ticks {
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
                &label,
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

/// Where [`FieldMap::to_svg`] draws: the drawn nodes' bounding box `bx0..bx1 x by0..by1`,
/// the scale (px per unit, equal in x and y), the drawing's size `pw x ph` and top-left
/// corner `(left, top)`, the colour bar's top and height, and the page's size.
struct Frame {
    bx0: f64,
    bx1: f64,
    by0: f64,
    by1: f64,
    scale: f64,
    pw: f64,
    ph: f64,
    left: f64,
    top: f64,
    bar_top: f64,
    bar_h: f64,
    width: f64,
    height: f64,
}

impl Frame {
    /// The page x of model x (x to the right).
    fn sx(&self, x: f64) -> f64 {
        self.left + (x - self.bx0) * self.scale
    }

    /// The page y of model y (y up, the page's y down).
    fn sy(&self, y: f64) -> f64 {
        self.top + (self.by1 - y) * self.scale
    }
}

/// A pixel coordinate in at most one decimal, without a trailing ".0".
fn short(x: f64) -> String {
    let s = format!("{:.1}", x);
    let s = s.strip_suffix(".0").unwrap_or(&s).to_string();
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// Label of an end of the colour range: a nice value keeps the step's decimals, any
/// other is given to 4 significant digits (0.00999 is not shown as "0.01").
fn end_label(v: f64, step: f64) -> String {
    let nice = tick_label(v, step);
    if nice
        .parse::<f64>()
        .is_ok_and(|p| (p - v).abs() <= 1e-9 * step)
    {
        nice
    } else {
        super::significant(v, 4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::svg::tests::assert_well_formed;
    use crate::output::test_util::temp_dir;

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
            x_label: "x [mm]".into(),
            y_label: String::new(),
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
        // Every sub-quad is one closed subpath, the outlines one per face.
        assert_eq!(svg.matches('Z').count(), 2 * 64 + 2);
        assert!(svg.contains(">x [mm]</text>") && svg.contains(">y</text>"));
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

    /// The ends of the colour range are ticked even when they are not nice numbers, with
    /// the digits they need; a nice tick too close to an end is left out.
    #[test]
    fn colour_bar_ticks_its_ends() {
        let m = strip(Some((0.0123, 0.16)));
        let ticks = tick_labels(&m.to_svg().unwrap());
        assert_eq!(ticks.first(), Some(&0.0123), "{ticks:?}");
        assert_eq!(ticks.last(), Some(&0.16), "{ticks:?}");
        // Nice ticks 0.05, 0.1, 0.15 (step 0.05 for at most 6 intervals); 0.15 is 0.01
        // (< 0.4 step) from the high end and is left out.
        assert_eq!(ticks, vec![0.0123, 0.05, 0.1, 0.16]);
    }

    /// A 25 x 25 face set (the paper cup's quarter blank) with a field varying in every
    /// face stays under 200 kB, with 2 x 2 sub-quads per face and at most 65 colours.
    #[test]
    fn a_large_map_stays_compact() {
        let n = 25;
        let id = |i: usize, j: usize| i * (n + 1) + j;
        let mut m = FieldMap::default();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (3.0 * i as f64, 3.0 * j as f64);
                m.points.push([x, y]);
                m.values
                    .push((x * 0.1).sin() * (y * 0.13).cos() + 1e-3 * x * y);
            }
        }
        for i in 0..n {
            for j in 0..n {
                m.quads
                    .push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let svg = m.to_svg().unwrap();
        assert_well_formed(&svg);
        assert!(svg.len() < 200_000, "{} bytes", svg.len());
        assert_eq!(svg.matches('Z').count(), 4 * n * n + n * n);
        assert!(svg.matches("<path fill=\"#").count() <= 65);
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
