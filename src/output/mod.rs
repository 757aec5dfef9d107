//! Output of a run: VTK frames (`.vtu`), the ParaView time series (`.pvd`), the per-step history
//! (`.csv`), the end-of-run `summary.json`, SVG charts with their data (`svg`), and the run's
//! output folder that scripts write below.
//!
//! Crash safety: every file that is rewritten whole (`.vtu`, `.pvd`, `summary.json`) is written to
//! a temporary file in the same folder and renamed over the target, so a run stopped at any moment
//! leaves either the previous or the new version, never a truncated one. The CSV history is
//! appended to and each row is written out before `append` returns.
//!
//! Numbers in text formats (`.csv`, `.pvd` timesteps) use Rust's shortest representation that
//! round-trips exactly (`{}` or `{:e}`), so parsing them back gives the same `f64`.

mod blank_frame;
mod cadence;
mod csv;
pub mod field_chart;
mod field_map;
pub mod fld_chart;
mod folder;
pub mod formability;
mod line_chart;
mod previous_run;
mod pvd;
mod run_settings;
mod shell_layers;
mod summary;
pub mod svg;
mod tool_fields;
mod tool_frame;
pub mod tool_map;
mod trim_tessellation;
mod vtk;

pub mod run;

pub use self::blank_frame::{frame, Configuration};
pub use self::cadence::{Cadence, DEFAULT_FRAMES};
pub use self::csv::HistoryCsv;
pub use self::folder::{FolderLock, OutputFolder, LOCK_FILE};
pub use self::previous_run::{
    clear_previous_outputs, describe as describe_outputs, previous_outputs,
};
pub use self::pvd::{PvdEntry, PvdSeries};
pub use self::run::{OutputOptions, RunOutput, Units};
pub use self::summary::{write_summary, SUMMARY_FILE};
pub use self::tool_frame::{tool_frame, DisplayRegion, TRIM_TOLERANCE};
pub use self::vtk::{
    read_vtu, read_vtu_point_field, write_vtu, Field, Frame, SYMMETRIC_TENSOR_COMPONENTS,
};

use crate::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically: into a temporary sibling file, then renamed over `path`.
/// The temporary file is removed if anything fails.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temp_sibling(path)?;
    let result = (|| -> std::io::Result<()> {
        let mut f = crate::paths::create_file(&tmp)?;
        f.write_all(bytes)?;
        f.flush()?;
        f.sync_data()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    Ok(())
}

/// `dir/name` -> `dir/.name.<pid>.tmp` (same folder, so the rename is atomic).
fn temp_sibling(path: &Path) -> Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| Error::io(path, "path does not name a file"))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".{}.tmp", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

/// Formats an `f64` so that parsing the text gives back the same value: plain decimal notation for
/// moderate magnitudes, exponent notation otherwise (both are shortest round-trip forms).
/// Non-finite values print as `NaN`, `inf`, `-inf`.
pub(crate) fn fmt_f64(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` to `digits` significant digits (1 to 17), for messages: plain decimals for
/// magnitudes from 1e-5 to 1e15, exponent form otherwise, trailing zeros dropped
/// (`significant(0.1 + 0.2, 6)` is "0.3", `significant(-23.912345678, 6)` is "-23.9123").
/// Files keep full precision ([`fmt_f64`]); this is for what people read.
pub fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let digits = digits.clamp(1, 17);
    let rounded = format!("{:.*e}", digits - 1, x);
    let (mantissa, exponent) = rounded.split_once('e').expect("exponent form");
    let exponent: i32 = exponent.parse().expect("integer exponent");
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (-5..15).contains(&exponent) {
        let value: f64 = rounded.parse().expect("a number");
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        trim(&format!("{value:.decimals$}"))
    } else {
        format!("{}e{exponent}", trim(mantissa))
    }
}

/// Escapes the five XML special characters for use in an attribute value.
pub(crate) fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod test_util {
    use std::path::PathBuf;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh, empty directory under the system temp dir, unique per process and call.
    pub fn temp_dir(tag: &str) -> PathBuf {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::SeqCst);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let dir = std::env::temp_dir().join(format!(
            "tribo-output-{tag}-{}-{n}-{nanos}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create temp dir");
        dir
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_f64_round_trips() {
        for &x in &[
            0.0,
            -0.0,
            1.0,
            0.1 + 0.2,
            -1.0 / 3.0,
            1e-300,
            -2.5e-5,
            6.02214076e23,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            123_456_789.123_456_79,
        ] {
            let s = fmt_f64(x);
            let y: f64 = s.parse().unwrap();
            assert_eq!(y.to_bits(), x.to_bits(), "{x} -> {s}");
        }
        assert_eq!(fmt_f64(0.5), "0.5");
        assert_eq!(fmt_f64(1e-7), "1e-7");
        assert!(fmt_f64(f64::NAN).parse::<f64>().unwrap().is_nan());
        assert_eq!(
            fmt_f64(f64::NEG_INFINITY).parse::<f64>().unwrap(),
            f64::NEG_INFINITY
        );
    }

    #[test]
    fn significant_digits_for_messages() {
        assert_eq!(significant(0.1 + 0.2, 6), "0.3");
        assert_eq!(significant(-23.912345678, 6), "-23.9123");
        assert_eq!(significant(30.000000000000004, 6), "30");
        assert_eq!(significant(9.9999996, 6), "10");
        assert_eq!(significant(123456789.0, 6), "123457000");
        assert_eq!(significant(1.5e-7, 6), "1.5e-7");
        assert_eq!(significant(-2.0e20 / 3.0, 3), "-6.67e19");
        assert_eq!(significant(0.000123456789, 3), "0.000123");
        assert_eq!(significant(-0.0, 6), "0");
        assert_eq!(significant(f64::NAN, 6), "NaN");
        assert_eq!(significant(f64::NEG_INFINITY, 6), "-inf");
        // Digits beyond 17 are clamped (17 round-trips every f64).
        let x = 0.1 + 0.2;
        assert_eq!(significant(x, 40).parse::<f64>().unwrap(), x);
    }

    #[test]
    fn write_atomic_replaces_and_leaves_no_temp() {
        let dir = test_util::temp_dir("atomic");
        let p = dir.join("a.txt");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "two");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 1);
        // A missing folder is an I/O error naming the path, not a panic.
        let bad = dir.join("missing").join("b.txt");
        let err = write_atomic(&bad, b"x").unwrap_err().to_string();
        assert!(err.contains("b.txt"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
