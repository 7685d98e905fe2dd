//! What the current bank is: name, description, source, modes and positions.

use egui::{Grid, RichText, Ui};
use serde_json::Value;

use crate::bank::summary::{note_name, BankSummary};
use crate::bank::Bank;

/// Draws the facts about `bank` (`summary` is its summary).
pub fn show(ui: &mut Ui, bank: &Bank, summary: &BankSummary, origin: &str, edited: bool) {
    let title = if edited {
        format!("{} (edited)", summary.name)
    } else {
        summary.name.clone()
    };
    ui.label(RichText::new(title).strong().size(15.0));
    ui.label(RichText::new(origin).small().weak());
    if !summary.description.is_empty() {
        ui.label(&summary.description);
    }
    Grid::new("bank facts")
        .num_columns(2)
        .spacing([8.0, 2.0])
        .show(ui, |ui| {
            row(ui, "Modes", summary.num_modes.to_string());
            row(
                ui,
                "Range",
                format!(
                    "{:.1} Hz to {:.1} Hz",
                    summary.freq_range_hz.0, summary.freq_range_hz.1
                ),
            );
            row(
                ui,
                "Root",
                format!("{:.2} Hz ({})", summary.root_hz, note_name(summary.root_hz)),
            );
            let (short, median, long) = summary.t60_s;
            row(
                ui,
                "T60",
                format!("{short:.2} s, median {median:.2} s, {long:.2} s"),
            );
            if let Some(q) = summary.reference_q {
                row(ui, "Q", format!("{q:.0}"));
            }
            if !summary.author.is_empty() {
                row(ui, "Author", summary.author.clone());
            }
            if !summary.license.is_empty() {
                row(ui, "Licence", summary.license.clone());
            }
            row(ui, "Source", source_text(bank));
        });
    ui.label(RichText::new(format!("Positions ({})", summary.positions.len())).strong());
    for (name, coords) in &summary.positions {
        let coords: Vec<String> = coords.iter().map(|c| format!("{c:.3}")).collect();
        ui.label(format!("{name}  ({})", coords.join(", ")));
    }
}

fn row(ui: &mut Ui, label: &str, value: String) {
    ui.label(RichText::new(label).weak());
    ui.label(value);
    ui.end_row();
}

/// The bank's `source` as one line per field: `kind` first, then the simple values.
fn source_text(bank: &Bank) -> String {
    let Some(source) = &bank.source else {
        return "not given".to_string();
    };
    let mut lines = Vec::new();
    if let Some(kind) = source.get("kind").and_then(Value::as_str) {
        lines.push(kind.to_string());
    }
    for (key, value) in source.iter().filter(|(k, _)| k.as_str() != "kind") {
        let text = match value {
            Value::String(s) => s.clone(),
            Value::Number(n) => n.to_string(),
            Value::Bool(b) => b.to_string(),
            Value::Null => "null".to_string(),
            Value::Array(a) => format!("[{} values]", a.len()),
            Value::Object(o) => format!("{{{} fields}}", o.len()),
        };
        lines.push(format!("{key}: {text}"));
    }
    if lines.is_empty() {
        "not given".to_string()
    } else {
        lines.join("\n")
    }
}
