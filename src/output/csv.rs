//! Per-step history as CSV: a header line with the column names, then one row of numbers per
//! [`HistoryCsv::append`]. Each row is written to the file before `append` returns (no user-space
//! buffering), so a crash keeps every row appended so far. Numbers are written in shortest
//! round-trip form, so parsing them gives back the exact `f64` (`NaN`, `inf`, `-inf` for
//! non-finite values).

use crate::{Error, Result};
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// An open CSV history file.
#[derive(Debug)]
pub struct HistoryCsv {
    path: PathBuf,
    file: File,
    columns: Vec<String>,
    rows: usize,
}

impl HistoryCsv {
    /// Creates (or truncates) `path` and writes the header line. At least one column is needed;
    /// names containing `,`, `"` or line breaks are quoted as in RFC 4180.
    pub fn create<S: AsRef<str>>(path: impl AsRef<Path>, columns: &[S]) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        if columns.is_empty() {
            return Err(Error::input(
                &format!("columns of CSV {}", path.display()),
                "[]",
                "must name at least one column",
            ));
        }
        let columns: Vec<String> = columns.iter().map(|c| c.as_ref().to_string()).collect();
        let header: Vec<String> = columns.iter().map(|c| quote(c)).collect();
        let mut file = crate::paths::create_file(&path).map_err(|e| Error::io(&path, e))?;
        writeln!(file, "{}", header.join(","))
            .and_then(|_| file.flush())
            .map_err(|e| Error::io(&path, e))?;
        Ok(HistoryCsv {
            path,
            file,
            columns,
            rows: 0,
        })
    }

    /// Appends one row; `row.len()` must equal the number of columns (else `Error::Input`, and
    /// nothing is written).
    pub fn append(&mut self, row: &[f64]) -> Result<()> {
        if row.len() != self.columns.len() {
            return Err(Error::input(
                &format!("length of row {} of {}", self.rows + 1, self.path.display()),
                row.len(),
                &format!("must equal the number of columns ({})", self.columns.len()),
            ));
        }
        let mut line = row
            .iter()
            .map(|&x| super::fmt_f64(x))
            .collect::<Vec<_>>()
            .join(",");
        line.push('\n');
        // One write of the whole line on an unbuffered file: the row reaches the OS at once.
        self.file
            .write_all(line.as_bytes())
            .and_then(|_| self.file.flush())
            .map_err(|e| Error::io(&self.path, e))?;
        self.rows += 1;
        Ok(())
    }

    /// Column names, as given at creation.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Number of rows appended so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Path of the file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

pub(super) fn quote(name: &str) -> String {
    if name.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    #[test]
    fn csv_header_rows_exact_round_trip() {
        let dir = temp_dir("csv");
        let path = dir.join("history.csv");
        let mut csv = HistoryCsv::create(&path, &["step", "time", "force_z", "gap"]).unwrap();
        let rows = [
            [0.0, 0.0, -0.0, 1e-300],
            [1.0, 0.1 + 0.2, -1.0 / 3.0, 5e-324],
            [2.0, 1e-7, 6.02214076e23, f64::MAX],
            [3.0, 123456.789, f64::INFINITY, f64::NAN],
        ];
        for (i, r) in rows.iter().enumerate() {
            csv.append(r).unwrap();
            // Each row is on disk right after append (no close/flush by the caller).
            let text = std::fs::read_to_string(&path).unwrap();
            assert_eq!(text.lines().count(), i + 2);
        }
        assert_eq!(csv.rows(), 4);
        drop(csv);

        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), "step,time,force_z,gap");
        for r in &rows {
            let parsed: Vec<f64> = lines
                .next()
                .unwrap()
                .split(',')
                .map(|s| s.parse().unwrap())
                .collect();
            assert_eq!(parsed.len(), r.len());
            for (a, b) in parsed.iter().zip(r) {
                if b.is_nan() {
                    assert!(a.is_nan());
                } else {
                    assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b}");
                }
            }
        }
        assert!(lines.next().is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn csv_row_length_mismatch_is_error() {
        let dir = temp_dir("csv-bad");
        let path = dir.join("h.csv");
        let mut csv = HistoryCsv::create(&path, &["a", "b,c"]).unwrap();
        csv.append(&[1.0, 2.0]).unwrap();
        let err = csv.append(&[1.0]).unwrap_err().to_string();
        assert!(err.contains("number of columns (2)"), "{err}");
        assert!(csv.append(&[1.0, 2.0, 3.0]).is_err());
        assert_eq!(csv.rows(), 1);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, "a,\"b,c\"\n1,2\n");

        let none: [&str; 0] = [];
        assert!(HistoryCsv::create(dir.join("e.csv"), &none).is_err());
        assert!(HistoryCsv::create(dir.join("missing/h.csv"), &["a"]).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
