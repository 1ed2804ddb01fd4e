//! Scene files and the camera's renderer: what every command that sets a table loads through.

use anyhow::Result;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::scene::Scene;
use tactex_sim::render::device::DeviceChoice;
use tactex_sim::render::scene::{SceneRenderer, open_scene_renderer};

/// The built-in demo scene: `scenes/demo.toml` here, or the one beside the sources.
pub fn default_scene() -> PathBuf {
    let local = Path::new("scenes/demo.toml");
    if local.is_file() {
        local.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/demo.toml")
    }
}

/// A scene file a question can be asked about: it parses (`Scene::load`) and, placed in the
/// twin's world, every object rests where the file puts it, fits the table, and the camera
/// stands outside them. `scene check`, `ask`, `serve`, `twin` and `bench ask` all load
/// through here, so that what one refuses the others refuse with the same message.
pub fn load_scene(
    path: &Path,
    catalog: &FruitCatalog,
) -> Result<(Scene, tactex_sim::world::SimWorld)> {
    super::file_input::present(path, "file: cannot read scene")?;
    let scene = Scene::load(path, catalog)?;
    let world = tactex_sim::world::SimWorld::from_scene(&scene)?;
    world
        .check_as_placed()
        .map_err(|why| anyhow::anyhow!("{}: {why}", path.display()))?;
    Ok((scene, world))
}

/// The scene renderer `device` names, telling the user on stderr when `auto` fell back to
/// the CPU.
pub fn scene_renderer(device: DeviceChoice) -> Result<Arc<dyn SceneRenderer>> {
    let choice = open_scene_renderer(device)?;
    if let Some(note) = &choice.note {
        eprintln!("note: {note}");
    }
    Ok(choice.renderer)
}
