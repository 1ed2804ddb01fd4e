//! The space randomised presses are drawn from, as `--fidelity` and `--shapes` name it:
//! shared by `datagen tactile` and `eval hardness`, so both draw alike.

use anyhow::{Result, bail};
use tactex_sim::contact::Fidelity;
use tactex_sim::datagen::tactile_sample::{SampleSpace, ShapeFamily};

/// The sample space the arguments describe.
pub fn sample_space(fidelity: &str, shapes: &[String]) -> Result<SampleSpace> {
    let fidelity: Fidelity = fidelity
        .parse()
        .map_err(|e| anyhow::anyhow!("--fidelity: {e}"))?;
    let mut families = Vec::new();
    for s in shapes {
        let f: ShapeFamily = s.parse().map_err(|e| anyhow::anyhow!("--shapes: {e}"))?;
        if !families.contains(&f) {
            families.push(f);
        }
    }
    if families.is_empty() {
        bail!("--shapes: name at least one shape family");
    }
    Ok(SampleSpace {
        families,
        fidelity,
        ..SampleSpace::default()
    })
}
