//! The tactile sensor's profile: the built-in GelSight Mini, a profile file, a what-if gel.

use anyhow::{Context, Result, bail};
use std::path::Path;
use tactex_core::tactile::sensor_profile::SensorProfile;

/// The profile at `path` (`--sensor`), or the built-in GelSight Mini.
pub fn load_sensor(path: Option<&Path>) -> Result<SensorProfile> {
    match path {
        Some(p) => load_profile(p).context("--sensor"),
        None => Ok(SensorProfile::gelsight_mini()),
    }
}

/// A profile file named without a flag (`sensor check FILE`): its errors name the file alone.
pub fn load_profile(path: &Path) -> Result<SensorProfile> {
    super::file_input::present(path, "file: cannot read")?;
    SensorProfile::load(path).map_err(anyhow::Error::new)
}

/// `sensor` with its gel's modulus replaced when one is given (`--gel-modulus-mpa`).
pub fn with_gel_modulus(
    mut sensor: SensorProfile,
    gel_modulus_mpa: Option<f64>,
) -> Result<SensorProfile> {
    if let Some(e) = gel_modulus_mpa {
        // Beyond these the gel is no gel: a foam or a rubber outside the layer model's range.
        if !(e.is_finite() && (0.01..=50.0).contains(&e)) {
            bail!("--gel-modulus-mpa: {e} is outside 0.01..50 MPa");
        }
        sensor.spec.gel.modulus_mpa = e;
    }
    Ok(sensor)
}
