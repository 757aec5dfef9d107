//! The run's output folder. Scripts may write only below it: [`OutputFolder::resolve`] turns a
//! script-supplied relative path into a path inside the folder and refuses absolute paths, drive
//! prefixes, any `..` component and any symbolic link inside the folder (see [`crate::paths`]).

use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// A created output folder.
#[derive(Clone, Debug)]
pub struct OutputFolder {
    root: PathBuf,
}

impl OutputFolder {
    /// Creates `path` and its parents if missing (an existing folder is fine).
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        let root = path.as_ref().to_path_buf();
        std::fs::create_dir_all(&root).map_err(|e| Error::io(&root, e))?;
        if !root.is_dir() {
            return Err(Error::io(&root, "not a directory"));
        }
        Ok(OutputFolder { root })
    }

    /// The folder itself.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `root/relative`, after the checks of [`crate::paths::resolve_write`]: non-empty,
    /// relative, no `..`, and no symbolic link at any component that exists already (a link
    /// in the output folder is never followed). The error names the refused path. Creates
    /// nothing.
    pub fn resolve(&self, relative: &str) -> Result<PathBuf> {
        crate::paths::resolve_write(&self.root, relative, false)
    }

    /// Like [`resolve`](Self::resolve), and creates the parent folders of the result (one by
    /// one, never through a link), ready for writing a file there.
    pub fn resolve_for_write(&self, relative: &str) -> Result<PathBuf> {
        crate::paths::resolve_write(&self.root, relative, true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    #[test]
    fn folder_refuses_escaping_paths() {
        let base = temp_dir("folder");
        let out = OutputFolder::create(base.join("nested/run1")).unwrap();
        assert!(out.root().is_dir());

        for bad in [
            "/tmp/x",
            "../x",
            "a/../../x",
            "a/..",
            "",
            ".",
            "./",
            "..\\x",
            "\\x",
        ] {
            let err = out.resolve(bad).unwrap_err().to_string();
            assert!(err.contains(&format!("\"{bad}\"")), "{bad}: {err}");
        }
        let err = out.resolve("/tmp/x").unwrap_err().to_string();
        assert!(err.contains("absolute"), "{err}");
        let err = out.resolve("a/../../x").unwrap_err().to_string();
        assert!(err.contains("'..'"), "{err}");

        let ok = out.resolve("frames/f0001.vtu").unwrap();
        assert_eq!(ok, out.root().join("frames").join("f0001.vtu"));
        assert!(ok.starts_with(out.root()));
        assert!(!ok.parent().unwrap().exists());
        assert_eq!(
            out.resolve("./frames//f0001.vtu").unwrap(),
            out.root().join("frames/f0001.vtu")
        );
        let w = out.resolve_for_write("frames/f0001.vtu").unwrap();
        assert!(w.parent().unwrap().is_dir());
        assert!(out.resolve_for_write("../x").is_err());

        // Creating again is fine; a file in the way is an error, not a panic.
        OutputFolder::create(out.root()).unwrap();
        std::fs::write(base.join("file"), "x").unwrap();
        assert!(OutputFolder::create(base.join("file")).is_err());
        let _ = std::fs::remove_dir_all(&base);
    }
}
