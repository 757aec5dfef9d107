//! The files an earlier run left in an output folder, so that a new run does not leave its
//! results beside stale ones (a history of 1 increment next to a summary of 60 and 84 old
//! frames).
//!
//! A run's own files are the ones the engine names, never a guess at the user's: at the
//! folder's top `history.csv`, `summary.json`, the `.pvd` series, the `.svg` charts and, for
//! each chart `NAME.svg`, its data `NAME.csv`; in `frames/` the `.vtu` frames; in
//! `checkpoints/` the `.json` checkpoints (`final.json` among them). Nothing else is listed
//! or removed: other files, other subfolders (a REPL's `repl/`, a script's `write_text`
//! files in folders of its own) and symbolic links stay. Entries are read with
//! `symlink_metadata`, so a link named like a run's file is never followed or removed.

use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// The earlier run's files in `dir` (see the module doc), sorted; empty when `dir` does not
/// exist.
pub fn previous_outputs(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut found = Vec::new();
    let top = regular_files(dir)?;
    for (name, path) in &top {
        let chart_data = name.strip_suffix(".csv").is_some_and(|stem| {
            (top.iter()).any(|(other, _)| other.strip_suffix(".svg") == Some(stem))
        });
        let own = matches!(name.as_str(), "history.csv" | "summary.json")
            || name.ends_with(".pvd")
            || name.ends_with(".svg")
            || chart_data;
        if own {
            found.push(path.clone());
        }
    }
    for (sub, ext) in [("frames", ".vtu"), ("checkpoints", ".json")] {
        let folder = dir.join(sub);
        if is_real_dir(&folder) {
            let files = regular_files(&folder)?.into_iter();
            found.extend(files.filter(|(n, _)| n.ends_with(ext)).map(|(_, p)| p));
        }
    }
    found.sort();
    Ok(found)
}

/// Removes the earlier run's files in `dir` and then `frames/` and `checkpoints/` if they
/// are left empty. Returns how many files were removed.
pub fn clear_previous_outputs(dir: &Path) -> Result<usize> {
    let files = previous_outputs(dir)?;
    for f in &files {
        std::fs::remove_file(f).map_err(|e| Error::io(f, e))?;
    }
    for sub in ["frames", "checkpoints"] {
        // Fails, as it should, when the folder still holds other files.
        let _ = std::fs::remove_dir(dir.join(sub));
    }
    Ok(files.len())
}

/// A short account of `files` for a message: the top-level names, and the frames and
/// checkpoints counted ("history.csv, summary.json, 84 frames").
pub fn describe(dir: &Path, files: &[PathBuf]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let (mut frames, mut checkpoints) = (0, 0);
    for f in files {
        match f.parent() {
            Some(p) if p == dir.join("frames") => frames += 1,
            Some(p) if p == dir.join("checkpoints") => checkpoints += 1,
            _ => parts.push(f.file_name().unwrap_or_default().to_string_lossy().into()),
        }
    }
    if parts.len() > 4 {
        let more = parts.len() - 3;
        parts.truncate(3);
        parts.push(format!("{more} more"));
    }
    let plural = |n: usize| if n == 1 { "" } else { "s" };
    if frames > 0 {
        parts.push(format!("{frames} frame{}", plural(frames)));
    }
    if checkpoints > 0 {
        parts.push(format!("{checkpoints} checkpoint{}", plural(checkpoints)));
    }
    parts.join(", ")
}

fn is_real_dir(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.is_dir())
}

/// (name, path) of the regular files directly in `dir` (no links); none if `dir` is absent.
fn regular_files(dir: &Path) -> Result<Vec<(String, PathBuf)>> {
    if !is_real_dir(dir) {
        return Ok(Vec::new());
    }
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if let (true, Some(name)) = (regular, entry.file_name().to_str()) {
            files.push((name.to_string(), entry.path()));
        }
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    #[test]
    fn only_the_engines_files_are_listed_and_cleared() {
        let dir = temp_dir("previous");
        let own = [
            "history.csv",
            "summary.json",
            "frames.pvd",
            "punch_force.svg",
            "punch_force.csv",
            "frames/frame_0000.vtu",
            "frames/punch_0000.vtu",
            "checkpoints/final.json",
        ];
        let users = [
            "notes.txt",
            "measured.csv",
            "frames/photo.png",
            "repl/history.csv",
            "mine/chart.svg",
        ];
        for f in own.iter().chain(&users) {
            let path = dir.join(f);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, "x").unwrap();
        }
        let outside = dir.join("mine/outside.json");
        std::os::unix::fs::symlink(&outside, dir.join("checkpoints/link.json")).unwrap();
        let mut expected: Vec<PathBuf> = own.iter().map(|f| dir.join(f)).collect();
        expected.sort();
        assert_eq!(previous_outputs(&dir).unwrap(), expected);
        assert_eq!(
            describe(&dir, &expected),
            "frames.pvd, history.csv, punch_force.csv, 2 more, 2 frames, 1 checkpoint"
        );
        assert_eq!(clear_previous_outputs(&dir).unwrap(), own.len());
        for f in own {
            assert!(!dir.join(f).exists(), "{f} left");
        }
        for f in users {
            assert!(dir.join(f).is_file(), "{f} removed");
        }
        // checkpoints/ still holds the link (never followed, never removed); frames/ the photo.
        assert!(std::fs::symlink_metadata(dir.join("checkpoints/link.json")).is_ok());
        assert!(previous_outputs(&dir).unwrap().is_empty());
        assert!(previous_outputs(&dir.join("absent")).unwrap().is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
