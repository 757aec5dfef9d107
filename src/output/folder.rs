//! The run's output folder. Scripts may write only below it: [`OutputFolder::resolve`] turns a
//! script-supplied relative path into a path inside the folder and refuses absolute paths, drive
//! prefixes and any `..` component. (Symbolic links already inside the folder are not followed
//! or checked: the folder is the run's own.)

use crate::{Error, Result};
use std::path::{Component, Path, PathBuf};

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

    /// `root/relative`, after checking `relative` stays below the folder: it must be non-empty,
    /// relative (no leading `/`, `\` or drive prefix) and contain no `..` component. `.`
    /// components are dropped. The error names the refused path. Creates nothing.
    pub fn resolve(&self, relative: &str) -> Result<PathBuf> {
        let refuse = |why: &str| Error::input("output path", format!("\"{relative}\""), why);
        let mut out = self.root.clone();
        let mut named = false;
        for c in Path::new(relative).components() {
            match c {
                Component::Normal(p) => {
                    out.push(p);
                    named = true;
                }
                Component::CurDir => {}
                Component::ParentDir => {
                    return Err(refuse(
                        "must not contain '..' (scripts may only write below the output folder)",
                    ));
                }
                Component::RootDir | Component::Prefix(_) => {
                    return Err(refuse(
                        "must be relative to the output folder (absolute paths are refused)",
                    ));
                }
            }
        }
        // On Unix a backslash is an ordinary character, but a name like "..\x" or "\x" would
        // mean something else on Windows: refuse such paths everywhere for portable scripts.
        if relative.contains('\\') {
            return Err(refuse("must use '/' as separator"));
        }
        if !named {
            return Err(refuse("must name a file or folder below the output folder"));
        }
        Ok(out)
    }

    /// Like [`resolve`](Self::resolve), and creates the parent folders of the result, ready for
    /// writing a file there.
    pub fn resolve_for_write(&self, relative: &str) -> Result<PathBuf> {
        let path = self.resolve(relative)?;
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        }
        Ok(path)
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
