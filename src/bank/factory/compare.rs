//! Where two banks differ: how the factory test tells a stale preset file from a fresh build.

use crate::bank::Bank;

/// Where two banks differ, or `None` when they are equal with numbers compared to a relative
/// tolerance `rel_tol` (JSON text keeps every digit, but parsers may round the last bit).
///
/// The answer names the JSON path of the first difference, e.g. `modes[12].gains[3]: 0.25 vs
/// 0.5`.
pub fn first_difference(a: &Bank, b: &Bank, rel_tol: f64) -> Option<String> {
    let a = serde_json::to_value(a).expect("a bank always serialises");
    let b = serde_json::to_value(b).expect("a bank always serialises");
    value_difference("", &a, &b, rel_tol)
}

fn value_difference(
    path: &str,
    a: &serde_json::Value,
    b: &serde_json::Value,
    rel_tol: f64,
) -> Option<String> {
    use serde_json::Value;
    let here = || if path.is_empty() { "(root)" } else { path }.to_string();
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64()?, y.as_f64()?);
            let close = (x - y).abs() <= rel_tol * x.abs().max(y.abs());
            (!close).then(|| format!("{}: {x} vs {y}", here()))
        }
        (Value::Array(xs), Value::Array(ys)) => {
            if xs.len() != ys.len() {
                return Some(format!("{}: {} vs {} items", here(), xs.len(), ys.len()));
            }
            xs.iter()
                .zip(ys)
                .enumerate()
                .find_map(|(i, (x, y))| value_difference(&format!("{path}[{i}]"), x, y, rel_tol))
        }
        (Value::Object(xs), Value::Object(ys)) => {
            let keys = xs.keys().chain(ys.keys().filter(|k| !xs.contains_key(*k)));
            keys.into_iter().find_map(|key| {
                let sub = if path.is_empty() {
                    key.clone()
                } else {
                    format!("{path}.{key}")
                };
                match (xs.get(key), ys.get(key)) {
                    (Some(x), Some(y)) => value_difference(&sub, x, y, rel_tol),
                    _ => Some(format!("{sub}: present in only one")),
                }
            })
        }
        _ => (a != b).then(|| format!("{}: {a} vs {b}", here())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::factory::factory_bank;

    #[test]
    fn differences_are_located() {
        let bank = factory_bank("steel-plate").unwrap();
        assert_eq!(first_difference(&bank, &bank, 0.0), None);
        let mut nudged = bank.clone();
        nudged.modes[12].gains[3] *= 1.0 + 1e-13;
        assert_eq!(first_difference(&bank, &nudged, 1e-12), None);
        nudged.modes[12].gains[3] *= 2.0;
        let found = first_difference(&bank, &nudged, 1e-12).unwrap();
        assert!(found.starts_with("modes[12].gains[3]: "), "{found}");
        let mut renamed = bank.clone();
        renamed.name.push('!');
        let found = first_difference(&bank, &renamed, 1e-12).unwrap();
        assert!(found.starts_with("name: "), "{found}");
        let mut fewer = bank.clone();
        fewer.positions.pop();
        let found = first_difference(&bank, &fewer, 1e-12).unwrap();
        assert!(found.starts_with("positions: 4 vs 3 items"), "{found}");
    }
}
