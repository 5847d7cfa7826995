//! The frame plans of a scene's methods ([`crate::methods::output::MethodPlan`], as `stats.json` holds
//! it) in one collapsible `<details>`: per method its passes in order with their time and
//! counters, the buffers it allocated, and its settings after option parsing and automatic
//! decisions; and the one-line summary of those settings that the table shows.

use super::html::Html;
use super::SceneRuns;
use serde_json::Value;

/// A JSON value as short text: strings bare, arrays and objects as JSON.
fn value_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The decisions among `map`'s entries as `key=value`: strings, booleans, integers, enum
/// variants with data (a one-entry object whose key is capitalized, shown `Variant(value)`),
/// and those of nested objects one level down; floats, arrays and deeper objects (geometry,
/// counts of work done) are left to the full settings.
fn decisions(map: &serde_json::Map<String, Value>, nested: bool, out: &mut Vec<String>) {
    for (k, v) in map {
        match v {
            Value::String(_) | Value::Bool(_) => out.push(format!("{k}={}", value_text(v))),
            Value::Number(n) if n.is_i64() || n.is_u64() => out.push(format!("{k}={n}")),
            Value::Object(m) => match m.iter().next() {
                Some((variant, inner))
                    if m.len() == 1 && variant.starts_with(|c: char| c.is_ascii_uppercase()) =>
                {
                    out.push(format!("{k}={variant}({})", value_text(inner)))
                }
                _ if !nested => decisions(m, true, out),
                _ => {}
            },
            _ => {}
        }
    }
}

/// The settings a method decided for this frame, in one line (strings, booleans, integers,
/// enum variants, also one level down): those of the plan's `settings.resolved` (after
/// automatic choices such as `test=ZFail`) or of its option table `settings.settings`, where
/// the method has one, else its settings without the frame-wide `gpu` table.
pub fn settings_summary(plan: &Value) -> String {
    let settings = &plan["settings"];
    let mut out = Vec::new();
    match (&settings["resolved"], &settings["settings"], settings) {
        (Value::Object(chosen), _, _) | (_, Value::Object(chosen), _) => {
            decisions(chosen, false, &mut out)
        }
        (_, _, Value::Object(all)) => {
            let mut all = all.clone();
            all.remove("gpu");
            decisions(&all, false, &mut out)
        }
        _ => {}
    }
    out.join(", ")
}

/// The `<details>` with every method's plan.
pub fn details(h: &mut Html, s: &SceneRuns) {
    h.open("details", &[]);
    h.element(
        "summary",
        &[],
        "Frame plans: each method's passes, buffers and settings",
    );
    for run in s.runs {
        let stats = &run.output.stats;
        let plan = &stats.plan;
        h.element("h4", &[], &run.method);
        h.open("table", &[("class", "passes")]);
        h.open("tr", &[]);
        for head in [
            "pass",
            "runs",
            "time [ms]",
            "MB traffic",
            "fragments shaded",
            "overflow events",
        ] {
            h.element("th", &[], head);
        }
        h.close();
        for p in &stats.passes {
            h.open("tr", &[]);
            h.element("td", &[("class", "name")], &p.name);
            for cell in [
                p.runs.to_string(),
                format!("{:.2}", 1e3 * p.wall_seconds),
                format!("{:.2}", p.counters.total_mb()),
                p.counters.fragments_shaded.to_string(),
                p.counters.overflow_events.to_string(),
            ] {
                h.element("td", &[], &cell);
            }
            h.close();
        }
        h.close();
        let buffers = plan["buffers"].as_array().map_or(&[][..], Vec::as_slice);
        if !buffers.is_empty() {
            h.open("table", &[("class", "buffers")]);
            h.open("tr", &[]);
            for head in ["buffer", "format", "bytes per sample"] {
                h.element("th", &[], head);
            }
            h.close();
            for b in buffers {
                h.open("tr", &[]);
                h.element("td", &[("class", "name")], &value_text(&b["name"]));
                h.element("td", &[("class", "text")], &value_text(&b["format"]));
                h.element("td", &[], &value_text(&b["bytes_per_sample"]));
                h.close();
            }
            h.close();
        }
        let settings =
            serde_json::to_string_pretty(&plan["settings"]).unwrap_or_else(|e| e.to_string());
        h.element("pre", &[], &settings);
    }
    h.close();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_shows_the_decisions() {
        let ssv = serde_json::json!({"settings": {"gpu": {"depth": "D24"}, "mode": "auto",
            "resolved": {"test": "ZFail", "coverage": {"Tables": "Bilinear"},
                "wedge": {"li": "Li16", "far": 29.5, "deeper": {"x": 1}}}}});
        assert_eq!(
            settings_summary(&ssv),
            "coverage=Tables(Bilinear), test=ZFail, li=Li16"
        );
        let ray = serde_json::json!({"settings": {"gpu": {"depth": "D24"}, "samples": 16,
            "axis": [1.0, 0.0]}});
        assert_eq!(settings_summary(&ray), "samples=16");
        assert_eq!(settings_summary(&serde_json::json!({})), "");
    }
}
