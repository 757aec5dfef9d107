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

/// Name of the lock file in an output folder.
pub const LOCK_FILE: &str = ".tribo.lock";

/// An exclusive hold on an output folder for one run: a second run into the same folder is
/// refused, naming the process that holds it.
///
/// The hold is an advisory `flock` on `.tribo.lock`, which the kernel releases when the
/// process ends however it ends (kill -9 included), so a lock left by a dead process is never
/// mistaken for a live one; the file also records the holder's pid for the messages. Dropping
/// the lock removes the file.
#[derive(Debug)]
pub struct FolderLock {
    /// Holds the flock: kept open for the lock's lifetime, never read.
    _file: std::fs::File,
    path: PathBuf,
}

impl FolderLock {
    /// Takes the lock of `dir` (created if missing). A folder held by a live process is an
    /// error naming its pid; a lock file left by a process that is gone is taken over with
    /// a warning on stderr.
    pub fn acquire(dir: &Path) -> Result<Self> {
        use std::io::{Read, Seek, Write};
        use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
        use std::os::unix::io::AsRawFd;
        let folder = OutputFolder::create(dir)?;
        let path = crate::paths::resolve_write(folder.root(), LOCK_FILE, false)?;
        // The file may be unlinked by a finishing holder between open and flock: then the
        // lock is on a dead inode, so check that the path still names the locked file.
        for _ in 0..10 {
            let mut file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .custom_flags(libc::O_NOFOLLOW)
                .open(&path)
                .map_err(|e| Error::io(&path, e))?;
            // SAFETY: flock on a descriptor we own.
            let rc = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
            let mut text = String::new();
            let _ = file.read_to_string(&mut text);
            let holder: Option<u32> = text.trim().parse().ok();
            if rc != 0 {
                let err = std::io::Error::last_os_error();
                if err.kind() != std::io::ErrorKind::WouldBlock {
                    return Err(Error::io(&path, err));
                }
                return Err(Error::Input(format!(
                    "the output folder {} is in use by another tribo run ({}); wait for it to \
                     finish or choose another --out",
                    dir.display(),
                    match holder {
                        Some(pid) => format!("process {pid}{}", describe_process(pid)),
                        None => "a process that has not written its pid yet".into(),
                    }
                )));
            }
            let same = match (file.metadata(), std::fs::symlink_metadata(&path)) {
                (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
                _ => false,
            };
            if !same {
                continue;
            }
            if let Some(pid) = holder.filter(|&p| p != std::process::id()) {
                eprintln!(
                    "warning: taking over the lock of {} left by process {pid}, which is no \
                     longer running",
                    dir.display()
                );
            }
            let write = (|| -> std::io::Result<()> {
                file.set_len(0)?;
                file.rewind()?;
                writeln!(file, "{}", std::process::id())?;
                file.flush()
            })();
            write.map_err(|e| Error::io(&path, e))?;
            return Ok(FolderLock { _file: file, path });
        }
        Err(Error::io(
            &path,
            "the lock file keeps changing; another run is starting",
        ))
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Unlink first; the descriptor (`self._file`) closes after this and releases the flock.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// " (command line)" of a running process, from /proc, or "" when unknown.
fn describe_process(pid: u32) -> String {
    std::fs::read(format!("/proc/{pid}/cmdline"))
        .ok()
        .map(|b| {
            let words: Vec<String> = b
                .split(|&c| c == 0)
                .filter(|w| !w.is_empty())
                .map(|w| String::from_utf8_lossy(w).into_owned())
                .collect();
            if words.is_empty() {
                String::new()
            } else {
                format!(": {}", words.join(" "))
            }
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    #[test]
    fn a_held_folder_is_refused_and_released_on_drop() {
        let base = temp_dir("lock");
        let lock = FolderLock::acquire(&base).unwrap();
        let err = FolderLock::acquire(&base).unwrap_err().to_string();
        assert!(
            err.contains(&format!(
                "in use by another tribo run (process {}",
                std::process::id()
            )),
            "{err}"
        );
        drop(lock);
        assert!(!base.join(LOCK_FILE).exists());
        // A lock file left by a dead process (no flock held) is taken over.
        std::fs::write(base.join(LOCK_FILE), "999999999\n").unwrap();
        let lock = FolderLock::acquire(&base).unwrap();
        assert_eq!(
            std::fs::read_to_string(base.join(LOCK_FILE))
                .unwrap()
                .trim(),
            std::process::id().to_string()
        );
        drop(lock);
        let _ = std::fs::remove_dir_all(&base);
    }

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
