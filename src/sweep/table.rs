//! The parameter table of a sweep: a CSV file whose header names script variables and whose
//! every row is one run (`mu,r` / `0.1,1000` gives `--set mu=0.1 --set r=1000`).
//!
//! Blank lines and lines starting with `#` are skipped. Cells are trimmed; a cell may be
//! quoted (`"hill48"`), and a quoted cell may hold commas. Errors name `file:line`.

use crate::{Error, Result};
use std::path::Path;

/// Column names and rows of values (as written, quotes removed).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn read(path: &Path) -> Result<Table> {
        let text = crate::paths::read_named_text(
            path,
            crate::paths::DEFAULT_MAX_READ_BYTES,
            "sweep table",
        )?;
        Table::parse(&text, &path.display().to_string())
    }

    /// Parses the table's text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Table> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (header_line, header) = lines
            .next()
            .ok_or_else(|| Error::Input(format!("{file}: the table has no header line")))?;
        let columns = split(header, file, header_line)?;
        for (i, name) in columns.iter().enumerate() {
            let identifier = name
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_alphanumeric() || c == '_');
            if !identifier {
                return Err(Error::Input(format!(
                    "{file}:{header_line}: column {} '{name}' is not a script variable name",
                    i + 1
                )));
            }
            if columns[..i].contains(name) {
                return Err(Error::Input(format!(
                    "{file}:{header_line}: column '{name}' appears twice"
                )));
            }
        }
        let mut rows = Vec::new();
        for (n, line) in lines {
            let cells = split(line, file, n)?;
            if cells.len() != columns.len() {
                return Err(Error::Input(format!(
                    "{file}:{n}: {} values for {} columns ({})",
                    cells.len(),
                    columns.len(),
                    columns.join(", ")
                )));
            }
            if let Some(c) = cells.iter().position(String::is_empty) {
                return Err(Error::Input(format!(
                    "{file}:{n}: the value of '{}' is empty",
                    columns[c]
                )));
            }
            rows.push(cells);
        }
        if rows.is_empty() {
            return Err(Error::Input(format!("{file}: the table has no rows")));
        }
        Ok(Table { columns, rows })
    }
}

/// Cells of one line: commas separate, except inside double quotes.
fn split(line: &str, file: &str, n: usize) -> Result<Vec<String>> {
    let (mut cells, mut cell, mut quoted) = (Vec::new(), String::new(), false);
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => cells.push(std::mem::take(&mut cell).trim().to_string()),
            c => cell.push(c),
        }
    }
    if quoted {
        return Err(Error::Input(format!("{file}:{n}: a quote is not closed")));
    }
    cells.push(cell.trim().to_string());
    Ok(cells)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_rows_comments_and_quotes() {
        let t = Table::parse(
            "# mu x r\nmu, r ,yield_kind\n0.1,1000,\"hill48\"\n\n0.2, 2e3, \"a,b\"\n",
            "t.csv",
        )
        .unwrap();
        assert_eq!(t.columns, ["mu", "r", "yield_kind"]);
        assert_eq!(t.rows, [["0.1", "1000", "hill48"], ["0.2", "2e3", "a,b"]]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = |text: &str| Table::parse(text, "t.csv").unwrap_err().to_string();
        assert!(e("mu,r\n0.1\n").contains("t.csv:2: 1 values for 2 columns"));
        assert!(e("mu,2r\n0.1,1\n").contains("t.csv:1: column 2 '2r'"));
        assert!(e("mu,mu\n1,2\n").contains("appears twice"));
        assert!(e("mu\n").contains("no rows"));
        assert!(e("mu,r\n0.1,\n").contains("t.csv:2: the value of 'r' is empty"));
        assert!(e("mu\n\"0.1\n").contains("t.csv:2: a quote is not closed"));
    }
}
