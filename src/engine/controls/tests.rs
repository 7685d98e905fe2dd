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
