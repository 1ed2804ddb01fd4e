//! What kind of mistake an error is, for front ends that answer each kind differently (the
//! Python package raises FileNotFoundError, ValueError or RuntimeError), judged by the error
//! types in its chain rather than by its words.

use crate::app::flag_range::FieldError;
use tactex_core::catalog::CatalogError;
use tactex_core::hand_eye::calibration_file::CalibrationFileError;
use tactex_core::hardness::interval_calibration::CalibrationError;
use tactex_core::hardness::scale::HardnessError;
use tactex_core::query::QueryError;
use tactex_core::scene::SceneError;
use tactex_core::tactile::ball_calibration::AnnotationError;
use tactex_core::tactile::sensor_profile::ProfileError;
use tactex_hw::devices_toml::DevicesError;
use tactex_hw::session::SessionError;
use tactex_learned::runtime::OnnxError;
use tactex_sim::contact::ContactError;
use tactex_sim::mesh::MeshError;
use tactex_sim::world::WorldError;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// A file or directory that was named is not there.
    Missing,
    /// What was given is wrong: a flag's value, a file's contents, a prompt.
    BadInput,
    /// The machinery failed on good input (a device, a solver, the disk).
    Failure,
}

impl ErrorKind {
    pub fn of(e: &anyhow::Error) -> ErrorKind {
        if e.chain().any(is_missing) {
            ErrorKind::Missing
        } else if e.chain().any(is_bad_input) {
            ErrorKind::BadInput
        } else if e.chain().any(|c| c.is::<std::io::Error>()) {
            // The disk or a device refused (permissions, a file where a folder should be).
            ErrorKind::Failure
        } else if names_a_flag(e) {
            ErrorKind::BadInput
        } else {
            ErrorKind::Failure
        }
    }
}

fn is_missing(cause: &(dyn std::error::Error + 'static)) -> bool {
    cause
        .downcast_ref::<std::io::Error>()
        .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
        || matches!(
            cause.downcast_ref::<SessionError>(),
            Some(SessionError::Missing { .. })
        )
}

/// The errors of reading what the user gave: prompts, scenes, meshes, profiles, hardness
/// values, annotations, interval tables, device files, sessions, models, contact settings,
/// and the formats they are written in.
fn is_bad_input(cause: &(dyn std::error::Error + 'static)) -> bool {
    cause.is::<QueryError>()
        || cause.is::<FieldError>()
        || cause.is::<crate::app::image_input::ImageInputError>()
        || cause.is::<SceneError>()
        || cause.is::<ProfileError>()
        || cause.is::<CatalogError>()
        || cause.is::<HardnessError>()
        || cause.is::<AnnotationError>()
        || cause.is::<CalibrationError>()
        || cause.is::<CalibrationFileError>()
        || cause.is::<DevicesError>()
        || cause.is::<SessionError>()
        || cause.is::<OnnxError>()
        || cause.is::<ContactError>()
        || cause.is::<WorldError>()
        || matches!(cause.downcast_ref::<MeshError>(), Some(m) if !matches!(m, MeshError::Io { .. }))
        || cause.is::<toml::de::Error>()
        || cause.is::<serde_json::Error>()
        || cause.is::<image::ImageError>()
        || cause.downcast_ref::<std::io::Error>().is_some_and(|io| {
            matches!(
                io.kind(),
                std::io::ErrorKind::InvalidData | std::io::ErrorKind::InvalidInput
            )
        })
}

/// The command line's convention: an error about a flag's value starts by naming the flag
/// (`--depth-mm: ...`), as every check of a flag in this crate writes it.
fn names_a_flag(e: &anyhow::Error) -> bool {
    e.chain().any(|cause| cause.to_string().starts_with("--"))
}

#[cfg(test)]
mod tests {
    use super::ErrorKind;
    use anyhow::Context;

    #[test]
    fn a_missing_file_is_missing_however_it_is_wrapped() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory");
        let e = anyhow::Error::new(io).context("--scene: a.toml");
        assert_eq!(ErrorKind::of(&e), ErrorKind::Missing);
    }

    #[test]
    fn a_bad_prompt_or_flag_is_bad_input_and_a_device_failure_is_not() {
        let catalog = tactex_core::catalog::FruitCatalog::builtin();
        let e = tactex_core::query::parse("Which car is the fastest?", &catalog).unwrap_err();
        assert_eq!(ErrorKind::of(&anyhow::Error::new(e)), ErrorKind::BadInput);
        let e = anyhow::anyhow!("--depth-mm: -1 is outside [0, 30]");
        assert_eq!(ErrorKind::of(&e), ErrorKind::BadInput);
        // An annotated press wider than its ball (docs/python.md's calibrate example at a
        // scale off by 0.2% raised RuntimeError for it).
        let e = tactex_core::tactile::ball_calibration::AnnotationError::Press {
            path: "annotations.csv".into(),
            message:
                "0034.png has a contact radius of 2.36 mm, not smaller than the ball's 2.35 mm"
                    .into(),
        };
        assert_eq!(ErrorKind::of(&anyhow::Error::new(e)), ErrorKind::BadInput);
        let e: anyhow::Result<()> =
            Err(anyhow::anyhow!("no Vulkan adapter")).context("opening the renderer");
        assert_eq!(ErrorKind::of(&e.unwrap_err()), ErrorKind::Failure);
        let denied = std::io::Error::new(std::io::ErrorKind::PermissionDenied, "denied");
        assert_eq!(
            ErrorKind::of(&anyhow::Error::new(denied).context("out/x.png: cannot write")),
            ErrorKind::Failure
        );
    }
}
