//! The file-access policy: the one place that decides which files a run may write and a
//! script may read.
//!
//! * **Writes** ([`resolve_write`]) go below the run's output folder. The relative path is
//!   checked lexically (no absolute path, no `..`, no `\`), then every component below the
//!   folder is checked with `symlink_metadata` (which does not follow links): a symbolic link
//!   anywhere is refused, intermediate components must be folders (created one by one with
//!   `create_dir`, which never follows a link either) and an existing target must be a regular
//!   file. Cost: one `lstat` per path component.
//! * **Reads** ([`ReadPolicy`]) — script imports, JSON tool tables, any data file a script
//!   names — resolve below the script's folder or a folder named with `--allow-read`. The
//!   path is first normalised lexically and refused without touching the file system when it
//!   lies outside (so the message never tells whether an outside file exists); then it is
//!   canonicalised (links resolved) and checked again, so a link inside the folder cannot
//!   point outside. Only regular files are opened (a FIFO or a device is refused from its
//!   metadata, before any `open`), non-blocking and without following links, and at most
//!   `max_bytes` are read. Error messages name the path the script gave, never file contents.

use crate::{Error, Result};
use std::collections::{BTreeMap, HashMap};
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// Default cap on a file a script reads (JSON tables, modules): 64 MiB.
pub const DEFAULT_MAX_READ_BYTES: u64 = 64 << 20;

/// `root/relative` for writing, after the checks of the module doc; with `create_parents`
/// the missing intermediate folders are created (never through a link).
pub fn resolve_write(root: &Path, relative: &str, create_parents: bool) -> Result<PathBuf> {
    let refuse = |why: &str| Error::input("output path", format!("\"{relative}\""), why);
    // On Unix a backslash is an ordinary character, but a name like "..\x" or "\x" would
    // mean something else on Windows: refuse such paths everywhere for portable scripts.
    if relative.contains('\\') {
        return Err(refuse("must use '/' as separator"));
    }
    let mut names = Vec::new();
    for c in Path::new(relative).components() {
        match c {
            Component::Normal(p) => names.push(p),
            Component::CurDir => {}
            Component::ParentDir => {
                return Err(refuse(
                    "must not contain '..' (scripts may only write below the output folder)",
                ))
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(refuse(
                    "must be relative to the output folder (absolute paths are refused)",
                ))
            }
        }
    }
    if names.is_empty() {
        return Err(refuse("must name a file or folder below the output folder"));
    }
    let mut path = root.to_path_buf();
    let last = names.len() - 1;
    for (i, name) in names.into_iter().enumerate() {
        path.push(name);
        let shown = path
            .strip_prefix(root)
            .unwrap_or(&path)
            .display()
            .to_string();
        match std::fs::symlink_metadata(&path) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(refuse(&format!(
                    "goes through the symbolic link '{shown}' in the output folder (links are \
                     never followed when writing)"
                )))
            }
            Ok(m) if i < last && !m.is_dir() => {
                return Err(refuse(&format!("'{shown}' is not a folder")))
            }
            Ok(m) if i == last && !m.is_file() => {
                return Err(refuse(&format!(
                    "'{shown}' exists and is not a regular file"
                )))
            }
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                if i < last && create_parents {
                    match std::fs::create_dir(&path) {
                        Ok(()) => {}
                        // Created meanwhile (another writer of this run): checked again below.
                        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                            let m = std::fs::symlink_metadata(&path)
                                .map_err(|e| Error::io(&path, e))?;
                            if !m.is_dir() {
                                return Err(refuse(&format!("'{shown}' is not a folder")));
                            }
                        }
                        Err(e) => return Err(Error::io(&path, e)),
                    }
                }
            }
            Err(e) => return Err(Error::io(&path, e)),
        }
    }
    if create_parents {
        charge_output(root, &path)?;
    }
    Ok(path)
}

/// Bytes a run may write into its output folder ([`set_output_limit`]).
static OUTPUT_LIMIT: AtomicU64 = AtomicU64::new(u64::MAX);

/// Per output folder: the files handed out for writing and their sizes when last looked at.
#[derive(Default)]
struct Ledger {
    sizes: HashMap<PathBuf, u64>,
    /// Files that may still grow, with how many refreshes they have stayed the same size.
    watch: Vec<(PathBuf, u32)>,
    total: u64,
}

static LEDGERS: Mutex<BTreeMap<PathBuf, Ledger>> = Mutex::new(BTreeMap::new());

/// Caps the bytes a run writes into its output folder (`--max-output-mb`). Counted by
/// [`resolve_write`] when it hands out the next path: files written since the last call (and
/// files still growing, like history.csv) are measured, so the run stops at the first write
/// after the cap, with at most one file's worth written over it.
///
/// The stop's own record ([`STOP_RECORD`]: summary.json, checkpoints/final.json) is written
/// past the cap: without it a run stopped by the cap would neither say why nor be able to
/// continue. Each is one file rewritten in place, so the excess stays bounded by their size.
pub fn set_output_limit(bytes: u64) {
    OUTPUT_LIMIT.store(bytes, Ordering::Relaxed);
}

/// Measures the files written since the last call and refuses a new write once over the cap.
/// Cost: one `lstat` per file written or grown since the last call (a file that stays the
/// same size for 8 calls is no longer watched).
/// The files a stopped run writes whatever its output size ([`set_output_limit`]).
pub const STOP_RECORD: [&str; 2] = ["summary.json", "checkpoints/final.json"];

fn charge_output(root: &Path, next: &Path) -> Result<()> {
    let limit = OUTPUT_LIMIT.load(Ordering::Relaxed);
    let mut ledgers = LEDGERS.lock().unwrap_or_else(|e| e.into_inner());
    let ledger = ledgers.entry(root.to_path_buf()).or_default();
    let mut watch = std::mem::take(&mut ledger.watch);
    watch.retain_mut(|(path, same)| {
        let size = std::fs::symlink_metadata(&*path).map_or(0, |m| m.len());
        let old = ledger.sizes.insert(path.clone(), size).unwrap_or(0);
        ledger.total = ledger.total - old.min(ledger.total) + size;
        *same = if size == old { *same + 1 } else { 0 };
        *same < 8
    });
    ledger.watch = watch;
    let stop_record = STOP_RECORD.iter().any(|f| next == root.join(f));
    if ledger.total > limit && !stop_record {
        return Err(Error::Input(format!(
            "the run has written {} bytes into its output folder {}, over the limit of {} bytes \
             (raise it with --max-output-mb)",
            ledger.total,
            root.display(),
            limit
        )));
    }
    if !ledger.watch.iter().any(|(p, _)| p == next) {
        ledger.watch.push((next.to_path_buf(), 0));
    }
    Ok(())
}

/// Opens (creating or truncating) a file checked by [`resolve_write`], refusing a link that
/// appeared in its place since (`O_NOFOLLOW`).
///
/// A file that has other hard links (`st_nlink > 1`) may be a name for a file outside the
/// output folder, which truncating would overwrite: its name is unlinked instead and a new
/// file created in its place (`O_EXCL`), so the other names keep their content.
pub fn create_file(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    let open = |exclusive: bool| {
        let mut options = std::fs::OpenOptions::new();
        options.write(true).custom_flags(libc::O_NOFOLLOW);
        if exclusive {
            options.create_new(true);
        } else {
            options.create(true);
        }
        options.open(path)
    };
    let file = open(false)?;
    if file.metadata()?.nlink() > 1 {
        drop(file);
        std::fs::remove_file(path)?;
        return open(true);
    }
    file.set_len(0)?;
    Ok(file)
}

/// Reads a file the command line names (`--restart`): any path the user may open, but only a
/// regular file (a FIFO would block, a device never end) and at most `max_bytes`.
pub fn read_named_file(path: &Path, max_bytes: u64, what: &str) -> Result<Vec<u8>> {
    use std::os::unix::fs::OpenOptionsExt;
    let fail = |e: &dyn std::fmt::Display| Error::Input(format!("{what} {}: {e}", path.display()));
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| fail(&e))?;
    let meta = file.metadata().map_err(|e| fail(&e))?;
    if !meta.is_file() {
        return Err(fail(
            &"not a regular file (folders, FIFOs and devices are refused)",
        ));
    }
    read_capped(file, max_bytes).map_err(|e| match e {
        CappedRead::Io(e) => fail(&e),
        CappedRead::TooLarge => fail(&format_args!("over the read limit of {max_bytes} bytes")),
    })
}

/// [`read_named_file`] as UTF-8 text, a leading byte-order mark dropped (editors on Windows
/// write one; it is not part of the text).
pub fn read_named_text(path: &Path, max_bytes: u64, what: &str) -> Result<String> {
    let bytes = read_named_file(path, max_bytes, what)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| Error::Input(format!("{what} {}: not UTF-8 text", path.display())))?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

enum CappedRead {
    Io(std::io::Error),
    TooLarge,
}

/// Reads at most `max_bytes` of `file`; more is an error, not a truncation.
fn read_capped(file: std::fs::File, max_bytes: u64) -> std::result::Result<Vec<u8>, CappedRead> {
    let mut bytes = Vec::new();
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(CappedRead::Io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(CappedRead::TooLarge);
    }
    Ok(bytes)
}

/// Where scripts may read: the script's folder and the `--allow-read` folders.
#[derive(Clone, Debug)]
pub struct ReadPolicy {
    /// Relative paths are taken from here (the script's folder).
    base: PathBuf,
    /// Canonical allowed folders (base first).
    roots: Vec<PathBuf>,
    /// Largest file read, in bytes.
    pub max_bytes: u64,
}

impl ReadPolicy {
    /// Reads below `base` (the script's folder; the working folder when empty) and below
    /// each of `extra`. A folder that does not exist is an error naming it.
    pub fn new(base: &Path, extra: &[PathBuf], max_bytes: u64) -> Result<Self> {
        let base = if base.as_os_str().is_empty() {
            Path::new(".")
        } else {
            base
        };
        let canon = |p: &Path| -> Result<PathBuf> {
            let c = p
                .canonicalize()
                .map_err(|e| Error::io(p, format!("readable folder: {e}")))?;
            if !c.is_dir() {
                return Err(Error::io(p, "readable folder: not a folder"));
            }
            Ok(c)
        };
        let base = canon(base)?;
        let mut roots = vec![base.clone()];
        for p in extra {
            roots.push(canon(p)?);
        }
        Ok(ReadPolicy {
            base,
            roots,
            max_bytes,
        })
    }

    /// A policy that allows no reads (every path is "outside"): what an engine gets when
    /// its folders cannot be opened, so that nothing is read by mistake.
    pub fn nothing() -> Self {
        ReadPolicy {
            base: PathBuf::from("/"),
            roots: Vec::new(),
            max_bytes: 0,
        }
    }

    /// The script's folder (canonical).
    pub fn base(&self) -> &Path {
        &self.base
    }

    fn inside(&self, p: &Path) -> bool {
        self.roots.iter().any(|r| p.starts_with(r))
    }

    fn outside_error(&self, given: &str, what: &str) -> Error {
        Error::Input(format!(
            "{what} \"{given}\" is outside the folders scripts may read (the script's folder \
             {}{}; name more with --allow-read DIR)",
            self.base.display(),
            if self.roots.len() > 1 {
                " and the --allow-read folders"
            } else {
                ""
            }
        ))
    }

    /// The canonical path of a readable regular file named `given` (relative to the script's
    /// folder, or absolute). `what` names the input in messages ("import", "JSON table").
    pub fn resolve(&self, given: &str, what: &str) -> Result<PathBuf> {
        if given.is_empty() {
            return Err(Error::Input(format!("{what} \"\": the path is empty")));
        }
        let joined = self.base.join(given);
        let lexical = normalize(&joined).ok_or_else(|| self.outside_error(given, what))?;
        if !self.inside(&lexical) {
            return Err(self.outside_error(given, what));
        }
        let canonical = match lexical.canonicalize() {
            Ok(c) => c,
            // A link that leads outside refuses alike whether its target exists or not
            // (issue 52: "no such file" for a dangling one told a script that an outside
            // file was missing).
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(match follow_links(&lexical, 0) {
                    Some(target) if self.inside(&target) => {
                        Error::Input(format!("{what} \"{given}\": no such file"))
                    }
                    _ => self.outside_error(given, what),
                })
            }
            Err(e) => return Err(Error::Input(format!("{what} \"{given}\": {e}"))),
        };
        if !self.inside(&canonical) {
            return Err(self.outside_error(given, what));
        }
        let meta = std::fs::metadata(&canonical)
            .map_err(|e| Error::Input(format!("{what} \"{given}\": {e}")))?;
        if !meta.is_file() {
            return Err(Error::Input(format!(
                "{what} \"{given}\" is not a regular file (folders, FIFOs and devices are refused)"
            )));
        }
        if meta.len() > self.max_bytes {
            return Err(Error::Input(format!(
                "{what} \"{given}\" is {} bytes, over the read limit of {} bytes (--max-read-mb)",
                meta.len(),
                self.max_bytes
            )));
        }
        Ok(canonical)
    }

    /// Reads the text of a file [`resolve`](Self::resolve) accepts (see
    /// [`read_bytes`](Self::read_bytes)); UTF-8 required.
    pub fn read_to_string(&self, given: &str, what: &str) -> Result<(PathBuf, String)> {
        let (path, bytes) = self.read_bytes(given, what)?;
        let text = String::from_utf8(bytes)
            .map_err(|_| Error::Input(format!("{what} \"{given}\" is not UTF-8 text")))?;
        Ok((path, text))
    }

    /// Reads the bytes of a file [`resolve`](Self::resolve) accepts: opened non-blocking and
    /// without following links, at most `max_bytes` read.
    pub fn read_bytes(&self, given: &str, what: &str) -> Result<(PathBuf, Vec<u8>)> {
        use std::os::unix::fs::OpenOptionsExt;
        let path = self.resolve(given, what)?;
        let file = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
            .open(&path)
            .map_err(|e| Error::Input(format!("{what} \"{given}\": {e}")))?;
        // Checked again on the open file: it may have been replaced since `resolve`.
        let meta = file
            .metadata()
            .map_err(|e| Error::Input(format!("{what} \"{given}\": {e}")))?;
        if !meta.is_file() {
            return Err(Error::Input(format!(
                "{what} \"{given}\" is not a regular file (folders, FIFOs and devices are refused)"
            )));
        }
        let bytes = read_capped(file, self.max_bytes).map_err(|e| match e {
            CappedRead::Io(e) => Error::Input(format!("{what} \"{given}\": {e}")),
            CappedRead::TooLarge => Error::Input(format!(
                "{what} \"{given}\" is over the read limit of {} bytes (--max-read-mb)",
                self.max_bytes
            )),
        })?;
        Ok((path, bytes))
    }
}

/// Where `path` (absolute, normalized) leads when the links along it are followed, as far
/// as it exists: the part past the first missing component is kept as written. `None` for a
/// chain of more than 40 links (the kernel's own bound) or an unreadable link. For a path
/// that `canonicalize` cannot resolve, so that a dangling link is judged by its target.
fn follow_links(path: &Path, hops: usize) -> Option<PathBuf> {
    if hops > 40 {
        return None;
    }
    let mut out = PathBuf::new();
    let mut parts = path.components();
    while let Some(c) = parts.next() {
        out.push(c);
        match std::fs::symlink_metadata(&out) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let target = std::fs::read_link(&out).ok()?;
                let parent = out.parent().unwrap_or(Path::new("/"));
                let joined = normalize(&parent.join(target))?.join(parts.as_path());
                return follow_links(&normalize(&joined)?, hops + 1);
            }
            Ok(_) => {}
            Err(_) => {
                out.push(parts.as_path());
                return normalize(&out);
            }
        }
    }
    Some(out)
}

/// `path` with `.` dropped and `..` applied lexically; `None` if `..` climbs above the root.
fn normalize(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                if !out.pop() || out.as_os_str().is_empty() {
                    return None;
                }
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_applies_dots_lexically() {
        assert_eq!(
            normalize(Path::new("/a/b/../c/./d")).unwrap(),
            PathBuf::from("/a/c/d")
        );
        assert_eq!(normalize(Path::new("/a/../..")), None);
    }
}
