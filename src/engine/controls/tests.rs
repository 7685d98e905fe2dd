//! Controls: named access, ranges and sanitising.

use super::*;

#[test]
fn sanitizing_clamps_and_replaces_nan() {
    let c = Controls {
        size_ratio: f32::NAN,
        width: 7.0,
        truncation_db: -1e9,
        material_q: Some(f32::INFINITY),
        ..Controls::default()
    }
    .sanitized();
    assert_eq!(c.size_ratio, 1.0);
    assert_eq!(c.width, 1.0);
    assert_eq!(c.truncation_db, -140.0);
    assert_eq!(c.material_q, Some(MATERIAL_Q_RANGE.1));
}

#[test]
fn set_by_name_reports_range_and_names() {
    let mut c = Controls::default();
    c.set_by_name("material_q", "800").unwrap();
    assert_eq!(c.material_q, Some(800.0));
    c.set_by_name("material", "wood").unwrap();
    assert_eq!(c.material_q, Some(Material::Wood.q()));
    assert!(c
        .set_by_name("size_ratio", "9")
        .unwrap_err()
        .contains("0.25 to 4"));
    assert!(c
        .set_by_name("sise_ratio", "1")
        .unwrap_err()
        .contains("unknown control"));
    assert!(c
        .set_by_name("exciter", "hammer")
        .unwrap_err()
        .contains("impulse, mallet, noise"));
    assert!(c
        .set_by_name("polyphony", "2.5")
        .unwrap_err()
        .contains("whole number"));
    c.set_by_name("polyphony", "8").unwrap();
    assert_eq!(c.polyphony, 8);
}

#[test]
fn pruning_controls_are_set_by_name_within_their_ranges() {
    let mut c = Controls::default();
    assert!(!c.pruning, "pruning is off by default");
    c.set_by_name("pruning", "on").unwrap();
    assert!(c.pruning);
    c.set_by_name("pruning", "0").unwrap();
    assert!(!c.pruning);
    assert!(c
        .set_by_name("pruning", "maybe")
        .unwrap_err()
        .contains("expected on or off"));
    c.set_by_name("masking_offset_db", "2.5").unwrap();
    assert_eq!(c.masking_offset_db, 2.5);
    assert!(c
        .set_by_name("masking_offset_db", "25")
        .unwrap_err()
        .contains("0 to 20"));
    c.set_by_name("playback_level_db_spl", "80").unwrap();
    assert_eq!(c.playback_level_db_spl, 80.0);
    assert!(c.set_by_name("playback_level_db_spl", "130").is_err());
    c.set_by_name("analysis_frame_ms", "46").unwrap();
    assert_eq!(c.analysis_frame_ms, 46.0);
    assert!(c.set_by_name("analysis_frame_ms", "1").is_err());
    c.set_by_name("mode_budget", "400").unwrap();
    assert_eq!(c.mode_budget, 400);
    assert!(c
        .set_by_name("mode_budget", "12.5")
        .unwrap_err()
        .contains("whole number"));
    c.set_by_name("target_load_pct", "50").unwrap();
    assert_eq!(c.target_load_pct, 50.0);
    assert!(c.set_by_name("target_load_pct", "150").is_err());
}

#[test]
fn banks_name_exactly_the_engines_exciters() {
    use crate::bank::validate::EXCITER_NAMES;
    use crate::dsp::ExciterKind;
    assert_eq!(EXCITER_NAMES, ExciterKind::ALL.map(|k| k.name()));
    // The schema offers the same names.
    let schema: serde_json::Value =
        serde_json::from_str(&crate::bank::schema::bank_schema_json()).unwrap();
    let offered = schema["$defs"]["BankDefaults"]["properties"]["exciter"]["enum"].clone();
    assert_eq!(
        offered,
        serde_json::json!(EXCITER_NAMES),
        "schema: {offered}"
    );
}
