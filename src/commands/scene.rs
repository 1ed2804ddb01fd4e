//! `tactex scene check`: a scene file validated whole and summarised.

use crate::app::load_scene;
use anyhow::Result;
use std::path::Path;
use tactex_core::catalog::FruitCatalog;

pub fn check(file: &Path) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    // Checked whole before anything is printed: a scene is valid or refused, never both.
    let (scene, world) = load_scene(file, &catalog)?;
    println!(
        "{}: scene '{}' is valid: {} objects on a {:.2} x {:.2} m table",
        file.display(),
        scene.name,
        scene.objects.len(),
        scene.table.size_m[0],
        scene.table.size_m[1]
    );
    for (o, s) in scene.objects.iter().zip(&world.objects) {
        let h = tactex_core::hardness::scale::HardnessReport::from(o.hardness);
        let e = h
            .modulus_mpa
            .map_or("rigid".to_string(), |e| format!("{e:.3} MPa"));
        println!(
            "  {:<11} at ({:+.3}, {:+.3}, {:.3}) m  {:>5} triangles  {e} ({:.1} Shore A){}",
            o.label,
            s.centre.x,
            s.centre.y,
            s.centre.z,
            s.mesh.triangles.len(),
            h.shore_a,
            o.ripeness
                .as_ref()
                .map_or(String::new(), |r| format!(", {r}"))
        );
    }
    Ok(())
}
