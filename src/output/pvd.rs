//! ParaView time-series collection (`.pvd`): one `<DataSet timestep=".." part=".." file=".."/>`
//! per frame and part.
//!
//! Parts are the blocks shown together at one time: part 0 is the blank, parts 1.. the tools'
//! display surfaces. ParaView's PVD reader makes one block per part, so opening the `.pvd`
//! shows blank and tools moving together; `name` labels the block.
//!
//! The whole `.pvd` is rewritten atomically (temp file + rename) on creation and after each
//! change ([`PvdSeries::add`], [`PvdSeries::add_parts`], [`PvdSeries::truncate`]), so it is a
//! complete, valid XML file listing every frame kept so far even if the run stops mid-way.

use crate::{Error, Result};
use std::path::{Component, Path, PathBuf};

/// One dataset of the collection.
#[derive(Clone, Debug, PartialEq)]
pub struct PvdEntry {
    /// Simulation time of the frame.
    pub time: f64,
    /// Block of the frame (0: the blank).
    pub part: usize,
    /// Name of the block ("" for none).
    pub name: String,
    /// Path of the `.vtu`, relative to the folder of the `.pvd`, with `/` separators.
    pub file: String,
}

/// A `.pvd` file `dir/basename.pvd` listing frames in the order they were added.
#[derive(Debug)]
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<PvdEntry>,
}

impl PvdSeries {
    /// Creates (or truncates) `dir/basename.pvd` as an empty, valid collection. `dir` must exist;
    /// `basename` is a plain file name without extension (no separators).
    pub fn new(dir: impl AsRef<Path>, basename: &str) -> Result<Self> {
        let mut comps = Path::new(basename).components();
        let plain = matches!(
            (comps.next(), comps.next()),
            (Some(Component::Normal(_)), None)
        ) && !basename.contains(['/', '\\']);
        if !plain {
            return Err(Error::input(
                "pvd basename",
                format!("\"{basename}\""),
                "must be a plain file name",
            ));
        }
        let series = PvdSeries {
            path: dir.as_ref().join(format!("{basename}.pvd")),
            entries: Vec::new(),
        };
        series.write()?;
        Ok(series)
    }

    /// Adds the frame at `time` stored in `relative_vtu_file` (relative to the `.pvd`'s folder;
    /// absolute paths, `..` components and non-finite times are refused) as part 0 and
    /// rewrites the `.pvd`.
    pub fn add(&mut self, time: f64, relative_vtu_file: impl AsRef<Path>) -> Result<()> {
        self.add_parts(time, &[("", relative_vtu_file.as_ref())])
    }

    /// Adds the blocks of one frame at `time`: `parts[i]` = (name, file) becomes part `i`.
    /// Nothing is added if any file is refused or the `.pvd` cannot be written.
    pub fn add_parts(&mut self, time: f64, parts: &[(&str, &Path)]) -> Result<()> {
        let mut entries = Vec::with_capacity(parts.len());
        for (part, (name, rel)) in parts.iter().enumerate() {
            if !time.is_finite() {
                return Err(Error::input(
                    &format!("time of pvd dataset {}", rel.display()),
                    time,
                    "must be finite",
                ));
            }
            entries.push(PvdEntry {
                time,
                part,
                name: name.to_string(),
                file: relative_file_string(rel)?,
            });
        }
        let kept = self.entries.len();
        self.entries.extend(entries);
        if let Err(e) = self.write() {
            self.entries.truncate(kept);
            return Err(e);
        }
        Ok(())
    }

    /// Keeps the first `frames` frames (a frame starts at each part-0 entry) and rewrites
    /// the `.pvd`.
    pub fn truncate(&mut self, frames: usize) -> Result<()> {
        let keep = (self.entries.iter().enumerate())
            .filter(|(_, e)| e.part == 0)
            .nth(frames)
            .map_or(self.entries.len(), |(i, _)| i);
        self.entries.truncate(keep);
        self.write()
    }

    /// Path of the `.pvd` file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Frames listed so far.
    pub fn entries(&self) -> &[PvdEntry] {
        &self.entries
    }

    /// The XML text of the collection as it is on disk.
    pub fn to_xml(&self) -> String {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n\
             <VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  \
             <Collection>\n",
        );
        for e in &self.entries {
            s.push_str(&format!(
                "    <DataSet timestep=\"{}\" group=\"\" part=\"{}\"{} file=\"{}\"/>\n",
                super::fmt_f64(e.time),
                e.part,
                if e.name.is_empty() {
                    String::new()
                } else {
                    format!(" name=\"{}\"", super::xml_escape(&e.name))
                },
                super::xml_escape(&e.file)
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        s
    }

    fn write(&self) -> Result<()> {
        super::write_atomic(&self.path, self.to_xml().as_bytes())
    }
}

/// `frames/f0001.vtu` -> "frames/f0001.vtu"; refuses absolute paths, `..`, non-UTF-8 names.
fn relative_file_string(rel: &Path) -> Result<String> {
    let refuse =
        |why: &str| Error::input("pvd dataset file", format!("\"{}\"", rel.display()), why);
    let mut parts = Vec::new();
    for c in rel.components() {
        match c {
            Component::Normal(p) => parts.push(
                p.to_str()
                    .ok_or_else(|| refuse("must be valid UTF-8"))?
                    .to_string(),
            ),
            Component::CurDir => {}
            Component::ParentDir => {
                return Err(refuse("must not contain '..'"));
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(refuse("must be relative to the .pvd folder"));
            }
        }
    }
    if parts.is_empty() {
        return Err(refuse("must name a file"));
    }
    Ok(parts.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    /// Minimal well-formedness check: balanced tags, quoted attributes, a single root.
    fn assert_well_formed_xml(text: &str) {
        let mut stack: Vec<String> = Vec::new();
        let mut rest = text.trim();
        if let Some(r) = rest.strip_prefix("<?xml") {
            rest = &r[r.find("?>").expect("unterminated declaration") + 2..];
        }
        let mut roots = 0;
        while let Some(start) = rest.find('<') {
            assert!(rest[..start].trim().is_empty(), "text outside tags");
            let end = rest[start..].find('>').expect("unterminated tag") + start;
            let tag = &rest[start + 1..end];
            assert_eq!(
                tag.matches('"').count() % 2,
                0,
                "unbalanced quotes in {tag}"
            );
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(
                    stack.pop().as_deref(),
                    Some(name.trim()),
                    "mismatched </{name}>"
                );
            } else {
                let name = tag.split_whitespace().next().unwrap().trim_end_matches('/');
                if stack.is_empty() {
                    roots += 1;
                }
                if !tag.ends_with('/') {
                    stack.push(name.to_string());
                }
            }
            rest = &rest[end + 1..];
        }
        assert!(rest.trim().is_empty());
        assert!(stack.is_empty(), "unclosed {stack:?}");
        assert_eq!(roots, 1);
    }

    /// (timestep, file) of each `<DataSet .../>` in order.
    fn datasets(text: &str) -> Vec<(f64, String)> {
        let attr = |tag: &str, key: &str| {
            let k = format!("{key}=\"");
            let i = tag.find(&k).unwrap() + k.len();
            tag[i..i + tag[i..].find('"').unwrap()].to_string()
        };
        text.split("<DataSet ")
            .skip(1)
            .map(|t| {
                let tag = &t[..t.find("/>").unwrap()];
                (attr(tag, "timestep").parse().unwrap(), attr(tag, "file"))
            })
            .collect()
    }

    #[test]
    fn pvd_valid_after_each_add() {
        let dir = temp_dir("pvd");
        let mut pvd = PvdSeries::new(&dir, "run").unwrap();
        let path = dir.join("run.pvd");
        assert_eq!(pvd.path(), path);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_well_formed_xml(&text);
        assert!(text.contains("type=\"Collection\""));
        assert!(datasets(&text).is_empty());

        let times = [0.0, 0.1 + 0.2, 1e-7, 2.5];
        for (i, &t) in times.iter().enumerate() {
            pvd.add(t, format!("frames/f{i:04}.vtu")).unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            assert_well_formed_xml(&text);
            let got = datasets(&text);
            assert_eq!(got.len(), i + 1);
            for (j, (tj, fj)) in got.iter().enumerate() {
                assert_eq!(tj.to_bits(), times[j].to_bits());
                assert_eq!(fj, &format!("frames/f{j:04}.vtu"));
            }
        }
        // No temporary files left behind.
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("run.pvd")]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn pvd_escapes_and_refuses_bad_input() {
        let dir = temp_dir("pvd-bad");
        let mut pvd = PvdSeries::new(&dir, "s").unwrap();
        pvd.add(1.0, "a&b \"c\".vtu").unwrap();
        let text = std::fs::read_to_string(pvd.path()).unwrap();
        assert_well_formed_xml(&text);
        assert!(
            text.contains("file=\"a&amp;b &quot;c&quot;.vtu\""),
            "{text}"
        );

        for bad in ["/tmp/x.vtu", "../x.vtu", "a/../../x.vtu", ""] {
            assert!(pvd.add(2.0, bad).is_err(), "{bad}");
        }
        let err = pvd.add(f64::NAN, "ok.vtu").unwrap_err().to_string();
        assert!(err.contains("NaN"), "{err}");
        assert_eq!(pvd.entries().len(), 1);
        assert!(PvdSeries::new(&dir, "a/b").is_err());
        assert!(PvdSeries::new(&dir, "..").is_err());
        assert!(PvdSeries::new(dir.join("missing"), "x").is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
