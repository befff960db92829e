//! `report.json`: what was done, with which options, how long it took, and the
//! quality metrics (DESIGN.md §4, §6).
//!
//! Everything in a report is deterministic except the `timings_ms` section, so two
//! runs with the same inputs and seed differ only there.

use fieldtex_core::{NoProgress, Progress, StageGuard, StageTimings, Warning};
use serde::Serialize;
use serde_json::Value;

/// The JSON report every command writes.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub tool: &'static str,
    pub version: &'static str,
    pub git_hash: &'static str,
    pub command: String,
    pub seed: u64,
    pub options: Value,
    pub input: Value,
    pub timings_ms: Vec<(String, f64)>,
    pub metrics: Value,
    pub warnings: Vec<Warning>,
    /// Plain statements of what is a substitute or not implemented in this run.
    pub notes: Vec<String>,
    /// The files of this run in its output folder (all from this run; see `outputs.rs`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<String>,
}

impl Report {
    pub fn new(command: &str, seed: u64, options: Value) -> Self {
        Self {
            tool: "fieldtex",
            version: env!("CARGO_PKG_VERSION"),
            git_hash: env!("FIELDTEX_GIT_HASH"),
            command: command.to_string(),
            seed,
            options,
            input: Value::Null,
            timings_ms: Vec::new(),
            metrics: Value::Object(Default::default()),
            warnings: Vec::new(),
            notes: Vec::new(),
            outputs: Vec::new(),
        }
    }

    /// Sets `metrics[key] = value`.
    pub fn metric(&mut self, key: &str, value: impl Serialize) {
        if let Value::Object(m) = &mut self.metrics {
            m.insert(key.to_string(), serde_json::to_value(value).unwrap_or(Value::Null));
        }
    }

    /// Runs `f` as the progress stage `name` through a [`StageGuard`]: reported to
    /// `progress` when it begins, finished when `f` returns (an early `?` inside `f`
    /// included), its wall time recorded under `name` in `timings_ms`.
    pub fn stage<T>(&mut self, progress: &dyn Progress, name: &str, f: impl FnOnce() -> T) -> T {
        let timings = StageTimings::default();
        let out = {
            let _stage = StageGuard::begin(progress, name, 0).timed(&timings);
            f()
        };
        self.record(&timings);
        out
    }

    /// [`Report::stage`] for a step that has no progress to report to (timed only).
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        self.stage(&NoProgress, name, f)
    }

    /// Appends the finished stages of `timings` (children before their parent) to
    /// `timings_ms`, under their full names.
    pub fn record(&mut self, timings: &StageTimings) {
        self.timings_ms.extend(timings.entries().into_iter().map(|t| (t.name, t.ms)));
    }

    /// Appends the timings, metrics, warnings and notes of `part` (a report a stage kept
    /// while running beside another, e.g. `orient`'s field design and exemplar analysis)
    /// in its order: merging the parts in the order the stages ran serially before gives
    /// the same report.
    pub(crate) fn absorb(&mut self, part: Report) {
        self.timings_ms.extend(part.timings_ms);
        if let (Value::Object(m), Value::Object(p)) = (&mut self.metrics, part.metrics) {
            m.extend(p);
        }
        self.warnings.extend(part.warnings);
        self.notes.extend(part.notes);
    }

    pub fn to_json_pretty(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|_| "{}".to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::Report;

    /// Parts absorbed in the serial order give the report the serial run would have
    /// written: timings, metrics, warnings and notes appended in order.
    #[test]
    fn absorb_appends_parts_in_order() {
        let mut serial = Report::new("orient", 1, serde_json::Value::Null);
        serial.timings_ms.push(("read".into(), 1.0));
        let mut merged = serial.clone();
        for (stage, key, note) in [("field_solve", "field_residual", "a"), ("analysis", "x", "b")] {
            serial.timings_ms.push((stage.into(), 2.0));
            serial.metric(key, 0.5);
            serial.notes.push(note.into());
            let mut part = Report::new("orient", 1, serde_json::Value::Null);
            part.timings_ms.push((stage.into(), 2.0));
            part.metric(key, 0.5);
            part.notes.push(note.into());
            merged.absorb(part);
        }
        assert_eq!(merged.to_json_pretty(), serial.to_json_pretty());
        let stages: Vec<&str> = merged.timings_ms.iter().map(|(s, _)| s.as_str()).collect();
        assert_eq!(stages, ["read", "field_solve", "analysis"]);
        assert_eq!(merged.metrics["field_residual"], 0.5);
    }
}
