//! Designing a bank from an analytic object: [`design_bank`] tunes the object, strikes it at its
//! positions and builds the bank. What `modal-resonator shape` and the factory use, and what an
//! editor can call.

use super::{build_bank, ModeLimits, Shape, ShapeError};
use crate::authoring::materials::Material;
use crate::bank::{Bank, Position};

/// A bank to build from an object.
#[derive(Debug, Clone, PartialEq)]
pub struct BankDesign {
    /// Display name of the bank.
    pub name: String,
    /// What it is and how it sounds; the object's summary (dimensions, pitch) is appended.
    pub description: String,
    /// The object, with its dimensions before tuning.
    pub shape: Shape,
    /// What it is made of.
    pub material: &'static Material,
    /// Strike positions; the object's default positions when `None`.
    pub positions: Option<Vec<Position>>,
    /// Which modes to keep.
    pub limits: ModeLimits,
    /// Retune the object (the way it is tuned, [`Shape::tuned_to`]) to this pitch in Hz.
    pub root_hz: Option<f64>,
}

/// The bank `design` describes, with the shape it was built from after tuning.
pub fn design_bank(design: &BankDesign) -> Result<(Bank, Shape), ShapeError> {
    let shape = match design.root_hz {
        Some(root_hz) => design.shape.tuned_to(design.material, root_hz)?,
        None => {
            design.shape.validate()?;
            design.shape.clone()
        }
    };
    let summary = shape.summary(design.material);
    let description = if design.description.is_empty() {
        summary
    } else {
        format!("{} {summary}", design.description)
    };
    let positions = design
        .positions
        .clone()
        .unwrap_or_else(|| shape.default_positions());
    let bank = build_bank(
        &design.name,
        &description,
        &shape,
        design.material,
        &positions,
        &design.limits,
    )?;
    Ok((bank, shape))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::authoring::materials;
    use crate::authoring::shapes::{ObjectKind, ObjectSpec, PlateEdge, OBJECTS};
    use crate::bank::validate::validate_bank;

    #[test]
    fn every_object_builds_at_its_typical_size() {
        for &object in OBJECTS {
            let shape = ObjectSpec::typical(object).shape().unwrap();
            assert_eq!(shape.kind(), object.name);
            let design = BankDesign {
                name: object.name.to_string(),
                description: String::new(),
                shape,
                material: object.default_material,
                positions: None,
                limits: ModeLimits::default(),
                root_hz: None,
            };
            let (bank, _) = design_bank(&design).unwrap();
            assert!(validate_bank(&bank).is_empty(), "{}", object.name);
            assert_eq!(ObjectKind::by_name(object.name), Some(object));
        }
        assert_eq!(
            ObjectKind::by_name("Free-Free-Bar").map(|o| o.name),
            Some("free-free-bar")
        );
        assert_eq!(ObjectKind::by_name("kazoo"), None);
    }

    #[test]
    fn designs_are_tuned_and_described() {
        let plate = ObjectKind::by_name("circular-plate").unwrap();
        let spec = ObjectSpec {
            edge: Some(PlateEdge::Clamped),
            ..ObjectSpec::typical(plate)
        };
        let design = BankDesign {
            name: "Clamped disc".into(),
            description: "A test disc.".into(),
            shape: spec.shape().unwrap(),
            material: &materials::STEEL,
            positions: None,
            limits: ModeLimits {
                max_freq_hz: 20_000.0,
                max_modes: 40,
            },
            root_hz: Some(220.0),
        };
        let (bank, shape) = design_bank(&design).unwrap();
        assert!((shape.root_hz(&materials::STEEL) / 220.0 - 1.0).abs() < 1e-12);
        assert_eq!(bank.root_hz, Some(shape.root_hz(&materials::STEEL)));
        assert_eq!(bank.modes.len(), 40);
        assert!(
            bank.description
                .starts_with("A test disc. Clamped circular plate of steel"),
            "{}",
            bank.description
        );
        assert_eq!(bank.source.as_ref().unwrap()["edge"], "clamped");
    }
}
