//! End-of-run summary as pretty-printed JSON, written atomically (temp file + rename).

use crate::{Error, Result};
use serde::Serialize;
use std::path::Path;

/// Conventional file name of the summary inside the run's output folder.
pub const SUMMARY_FILE: &str = "summary.json";

/// Writes `value` (a `serde_json::Value` or any `Serialize` type) to `path` as pretty-printed JSON
/// with a trailing newline, atomically. Non-finite floats become `null` (JSON has no NaN/inf).
/// A value that cannot be serialized (e.g. a map with non-string keys) gives an error naming
/// the file; nothing is written then.
pub fn write_summary<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value)
        .map_err(|e| Error::io(path, format!("cannot serialize to JSON: {e}")))?;
    text.push('\n');
    super::write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    #[derive(Serialize)]
    struct Summary {
        steps: usize,
        max_force: f64,
        converged: bool,
    }

    #[test]
    fn summary_pretty_atomic_round_trip() {
        let dir = temp_dir("summary");
        let path = dir.join(SUMMARY_FILE);
        let v = serde_json::json!({"steps": 3, "time": 0.1 + 0.2, "name": "bend"});
        write_summary(&path, &v).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\n  \"steps\": 3"), "{text}");
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, v);

        // Overwrite with a struct.
        let s = Summary {
            steps: 7,
            max_force: -1.0 / 3.0,
            converged: true,
        };
        write_summary(&path, &s).unwrap();
        let back: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(back["max_force"].as_f64().unwrap(), -1.0 / 3.0);
        assert_eq!(back["steps"], 7);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);

        // Non-string map keys cannot be JSON: error, previous file kept.
        let mut bad = std::collections::BTreeMap::new();
        bad.insert(vec![1u8], 1.0);
        assert!(write_summary(&path, &bad).is_err());
        assert!(std::fs::read_to_string(&path)
            .unwrap()
            .contains("max_force"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
