//! Scene files (TOML): the camera, the table and the objects resting on it.
//!
//! ```toml
//! name = "demo"
//! [camera]                       # optional; defaults: paper intrinsics, looking straight down
//! position_m = [0.0, 0.0, 0.70]
//! look_at_m = [0.0, 0.0, 0.0]
//! [[objects]]
//! kind = "banana"                # catalog fruit, or "sphere" | "ellipsoid" | "box" | "mesh"
//! position_m = [0.12, -0.05]     # x, y on the table; the object rests on it
//! yaw_deg = 30                   # optional
//! ripeness = "ripe"              # optional: a catalog stage
//! hardness = "35A"               # optional, overrides ripeness; or modulus_mpa = 0.8
//! size_m = [0.19, 0.06, 0.036]   # optional for a fruit: its own size, not the catalog's
//! ```
//! Every error names the file and the field (`objects[2].ripeness`).

use crate::catalog::{FruitCatalog, FruitShape};
use crate::geometry::{CameraIntrinsics, Pose};
use crate::hand_eye::calibration_file::PLACEMENT_LIMIT_M;
use crate::hardness::scale::Hardness;
use crate::printable::{short_number, short_numbers};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, thiserror::Error)]
#[error("{path}: {field}: {message}")]
pub struct SceneError {
    pub path: String,
    pub field: String,
    pub message: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ObjectKind {
    Fruit {
        name: String,
        shape: FruitShape,
        size_m: [f64; 3],
    },
    Sphere {
        radius_m: f64,
    },
    Ellipsoid {
        radii_m: [f64; 3],
    },
    Box {
        size_m: [f64; 3],
    },
    Mesh {
        path: PathBuf,
        scale: f64,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneObject {
    /// The catalog name for fruits, the kind otherwise (or the scene's `label`).
    pub label: String,
    pub kind: ObjectKind,
    pub position_m: [f64; 2],
    pub yaw_deg: f64,
    pub hardness: Hardness,
    pub ripeness: Option<String>,
    /// sRGB in [0, 1].
    pub color: [f64; 3],
    pub poisson: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Table {
    pub size_m: [f64; 2],
    pub color: [f64; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scene {
    pub name: String,
    pub path: PathBuf,
    pub camera_pose: Pose,
    pub intrinsics: CameraIntrinsics,
    pub table: Table,
    pub objects: Vec<SceneObject>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    name: String,
    camera: Option<RawCamera>,
    table: Option<RawTable>,
    #[serde(default)]
    objects: Vec<RawObject>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    position_m: Option<[f64; 3]>,
    look_at_m: Option<[f64; 3]>,
    intrinsics: Option<CameraIntrinsics>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTable {
    size_m: Option<[f64; 2]>,
    color: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    kind: String,
    position_m: Vec<f64>,
    yaw_deg: Option<f64>,
    ripeness: Option<String>,
    hardness: Option<String>,
    modulus_mpa: Option<f64>,
    radius_m: Option<f64>,
    radii_m: Option<[f64; 3]>,
    size_m: Option<[f64; 3]>,
    mesh: Option<String>,
    scale: Option<f64>,
    color: Option<[f64; 3]>,
    label: Option<String>,
    poisson: Option<f64>,
}

pub const DEFAULT_TABLE_SIZE_M: [f64; 2] = [0.60, 0.44];
const DEFAULT_TABLE_COLOR: [f64; 3] = [0.62, 0.60, 0.56];
const DEFAULT_OBJECT_COLOR: [f64; 3] = [0.70, 0.70, 0.72];
const DEFAULT_POISSON: f64 = 0.35;

impl Scene {
    /// The scene as a scene file that loads back to it (a random scene saved so that `ask
    /// --scene` can replay it). The camera is written as its position, the point it looks at
    /// on the table plane, and its intrinsics.
    pub fn to_toml(&self) -> String {
        let v3 = |v: [f64; 3]| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
        let eye = self.camera_pose.position;
        let forward = self.camera_pose.rotation * DVec3::Z;
        // Where the optical axis meets the table (or 1 m ahead of a camera looking up).
        let reach = if forward.z < -1e-9 {
            -eye.z / forward.z
        } else {
            1.0
        };
        let k = &self.intrinsics;
        let mut out = format!("name = {:?}\n\n[camera]\n", self.name);
        out += &format!("position_m = {}\n", v3(eye.to_array()));
        out += &format!("look_at_m = {}\n", v3((eye + forward * reach).to_array()));
        out += &format!(
            "intrinsics = {{ width = {}, height = {}, fx = {:?}, fy = {:?}, cx = {:?}, cy = {:?} }}\n",
            k.width, k.height, k.fx, k.fy, k.cx, k.cy
        );
        out += &format!(
            "\n[table]\nsize_m = [{:?}, {:?}]\ncolor = {}\n",
            self.table.size_m[0],
            self.table.size_m[1],
            v3(self.table.color)
        );
        for o in &self.objects {
            out += "\n[[objects]]\n";
            match &o.kind {
                ObjectKind::Fruit { name, size_m, .. } => {
                    out += &format!("kind = {name:?}\nsize_m = {}\n", v3(*size_m));
                }
                ObjectKind::Sphere { radius_m } => {
                    out += &format!("kind = \"sphere\"\nradius_m = {radius_m:?}\n");
                }
                ObjectKind::Ellipsoid { radii_m } => {
                    out += &format!("kind = \"ellipsoid\"\nradii_m = {}\n", v3(*radii_m));
                }
                ObjectKind::Box { size_m } => {
                    out += &format!("kind = \"box\"\nsize_m = {}\n", v3(*size_m));
                }
                ObjectKind::Mesh { path, scale } => {
                    out += &format!(
                        "kind = \"mesh\"\nmesh = {:?}\nscale = {scale:?}\n",
                        path.display().to_string()
                    );
                }
            }
            if !matches!(o.kind, ObjectKind::Fruit { .. }) || o.label != self.fruit_name(o) {
                out += &format!("label = {:?}\n", o.label);
            }
            out += &format!(
                "position_m = [{:?}, {:?}]\nyaw_deg = {:?}\n",
                o.position_m[0], o.position_m[1], o.yaw_deg
            );
            out += &match o.hardness {
                Hardness::ModulusMpa(e) => format!("modulus_mpa = {e:?}\n"),
                Hardness::ShoreA(v) => format!("hardness = \"{v:?} A\"\n"),
                Hardness::Shore00(v) => format!("hardness = \"{v:?} 00\"\n"),
                Hardness::Rigid => "hardness = \"rigid\"\n".into(),
            };
            out += &format!("color = {}\npoisson = {:?}\n", v3(o.color), o.poisson);
        }
        out
    }

    fn fruit_name<'o>(&self, o: &'o SceneObject) -> &'o str {
        match &o.kind {
            ObjectKind::Fruit { name, .. } => name,
            _ => &o.label,
        }
    }

    pub fn load(path: &Path, catalog: &FruitCatalog) -> Result<Scene, SceneError> {
        let shown = path.display().to_string();
        let text = crate::text_file::read_to_string(path).map_err(|e| SceneError {
            path: shown.clone(),
            field: "file".into(),
            message: format!("cannot read scene: {e}"),
        })?;
        Self::parse(&text, path, catalog)
    }

    /// Parses scene text; `path` names the file in errors and anchors relative mesh paths.
    pub fn parse(text: &str, path: &Path, catalog: &FruitCatalog) -> Result<Scene, SceneError> {
        let shown = path.display().to_string();
        let err = |field: &str, message: String| SceneError {
            path: shown.clone(),
            field: field.to_string(),
            message,
        };
        let raw: RawScene = toml::from_str(text)
            .map_err(|e| err("toml", crate::file_failure::toml_failure(text, &e)))?;

        // Names and labels are printed in answers and reports: one plain line each.
        crate::printable::check_name(&raw.name).map_err(|m| err("name", m))?;
        for (i, o) in raw.objects.iter().enumerate() {
            if let Some(label) = &o.label {
                crate::printable::check_name(label)
                    .map_err(|m| err(&format!("objects[{i}].label"), m))?;
            }
        }
        let (camera_pose, intrinsics) = Self::camera(raw.camera, &err)?;
        let table = Table {
            size_m: raw
                .table
                .as_ref()
                .and_then(|t| t.size_m)
                .unwrap_or(DEFAULT_TABLE_SIZE_M),
            color: raw
                .table
                .as_ref()
                .and_then(|t| t.color)
                .unwrap_or(DEFAULT_TABLE_COLOR),
        };
        if table
            .size_m
            .iter()
            .any(|s| !(s.is_finite() && (TABLE_SIZE_M[0]..=TABLE_SIZE_M[1]).contains(s)))
        {
            return Err(err(
                "table.size_m",
                format!(
                    "[{}, {}] m: each side must be {} to {} m",
                    short_number(table.size_m[0]),
                    short_number(table.size_m[1]),
                    TABLE_SIZE_M[0],
                    TABLE_SIZE_M[1]
                ),
            ));
        }
        check_color(&table.color).map_err(|m| err("table.color", m))?;

        if raw.objects.len() > MAX_OBJECTS {
            return Err(err(
                "objects",
                format!(
                    "{} objects; a scene has at most {MAX_OBJECTS} (each is simulated, seen and pressed)",
                    raw.objects.len()
                ),
            ));
        }
        let base = path.parent().unwrap_or(Path::new("."));
        let objects = raw
            .objects
            .into_iter()
            .enumerate()
            .map(|(i, o)| Self::object(i, o, &table, base, catalog, &err))
            .collect::<Result<Vec<_>, _>>()?;
        if objects.is_empty() {
            return Err(err("objects", "the scene has no objects".into()));
        }
        Ok(Scene {
            name: raw.name,
            path: path.to_path_buf(),
            camera_pose,
            intrinsics,
            table,
            objects,
        })
    }

    fn camera(
        raw: Option<RawCamera>,
        err: &impl Fn(&str, String) -> SceneError,
    ) -> Result<(Pose, CameraIntrinsics), SceneError> {
        let raw = raw.unwrap_or(RawCamera {
            position_m: None,
            look_at_m: None,
            intrinsics: None,
        });
        let eye = raw.position_m.unwrap_or([0.0, 0.0, 0.70]);
        let target = raw.look_at_m.unwrap_or([0.0, 0.0, 0.0]);
        if eye.iter().chain(&target).any(|v| !v.is_finite()) {
            return Err(err(
                "camera",
                "position_m and look_at_m must be finite".into(),
            ));
        }
        // The limit a table-top rig stands in, as for a rig's `devices.toml`: far beyond it the
        // direction between the two points is lost to rounding.
        for (name, at) in [("camera.position_m", eye), ("camera.look_at_m", target)] {
            if at.iter().any(|v| v.abs() > PLACEMENT_LIMIT_M) {
                return Err(err(
                    name,
                    format!(
                        "{} must be within {PLACEMENT_LIMIT_M} m of the world's origin on each axis",
                        short_numbers(&at)
                    ),
                ));
            }
        }
        let pose = Pose::camera_looking_at(DVec3::from_array(eye), DVec3::from_array(target))
            .ok_or_else(|| {
                err(
                    "camera.look_at_m",
                    "must differ from camera.position_m".into(),
                )
            })?;
        // A camera that cannot see the table answers nothing: it must stand above the table
        // top and look down at least 10 degrees.
        let forward = (DVec3::from_array(target) - DVec3::from_array(eye)).normalize();
        if eye[2] <= 0.0 || forward.z > -(10f64.to_radians().sin()) {
            return Err(err(
                "camera",
                format!(
                    "a camera at {eye:?} looking at {target:?} does not look down at the table (it must stand above z = 0 and look at least 10 degrees down)"
                ),
            ));
        }
        let k = raw.intrinsics.unwrap_or_default();
        k.check().map_err(|m| err("camera.intrinsics", m))?;
        Ok((pose, k))
    }

    fn object(
        i: usize,
        o: RawObject,
        table: &Table,
        base: &Path,
        catalog: &FruitCatalog,
        err: &impl Fn(&str, String) -> SceneError,
    ) -> Result<SceneObject, SceneError> {
        let field = |name: &str| format!("objects[{i}].{name}");
        // Sizes in metres an object on a table can have: 1 mm to 1 m.
        let size = |name: &str, v: f64| -> Result<f64, SceneError> {
            if v.is_finite() && (OBJECT_SIZE_M[0]..=OBJECT_SIZE_M[1]).contains(&v) {
                Ok(v)
            } else {
                Err(err(
                    &field(name),
                    format!(
                        "{} m is not a size an object on a table has ({} to {} m)",
                        short_number(v),
                        OBJECT_SIZE_M[0],
                        OBJECT_SIZE_M[1]
                    ),
                ))
            }
        };
        let need = |name: &str, v: Option<f64>| {
            v.ok_or_else(|| err(&field(name), format!("required for kind '{}'", o.kind)))
        };
        let need3 = |name: &str, v: Option<[f64; 3]>| -> Result<[f64; 3], SceneError> {
            let v =
                v.ok_or_else(|| err(&field(name), format!("required for kind '{}'", o.kind)))?;
            for x in v {
                size(name, x)?;
            }
            Ok(v)
        };

        let [x, y] = <[f64; 2]>::try_from(o.position_m.as_slice()).map_err(|_| {
            err(
                &field("position_m"),
                format!(
                    "expected [x, y] in metres, got {} numbers",
                    o.position_m.len()
                ),
            )
        })?;
        if !(x.is_finite() && y.is_finite()) {
            return Err(err(
                &field("position_m"),
                format!("must be finite, got {}", short_numbers(&[x, y])),
            ));
        }
        let [hx, hy] = [table.size_m[0] / 2.0, table.size_m[1] / 2.0];
        if x.abs() > hx || y.abs() > hy {
            return Err(err(
                &field("position_m"),
                format!(
                    "{} is off the table (|x| <= {hx}, |y| <= {hy})",
                    short_numbers(&[x, y])
                ),
            ));
        }
        let yaw_deg = o.yaw_deg.unwrap_or(0.0);
        if !yaw_deg.is_finite() {
            return Err(err(&field("yaw_deg"), "must be finite".into()));
        }
        if let Some(c) = &o.color {
            check_color(c).map_err(|m| err(&field("color"), m))?;
        }
        let poisson = o.poisson.unwrap_or(DEFAULT_POISSON);
        if !(poisson.is_finite() && (0.0..0.5).contains(&poisson)) {
            return Err(err(
                &field("poisson"),
                format!("must lie in [0, 0.5), got {}", short_number(poisson)),
            ));
        }
        let explicit_hardness = match (&o.hardness, o.modulus_mpa) {
            (Some(_), Some(_)) => {
                return Err(err(
                    &field("hardness"),
                    "give hardness or modulus_mpa, not both".into(),
                ));
            }
            (Some(h), None) => {
                Some(Hardness::parse(h).map_err(|e| err(&field("hardness"), e.to_string()))?)
            }
            (None, Some(e)) => Some(
                Hardness::from_modulus_mpa(e)
                    .map_err(|e| err(&field("modulus_mpa"), e.to_string()))?,
            ),
            (None, None) => None,
        };

        let kind_name = o.kind.to_ascii_lowercase();
        // A size the kind does not read would be dropped without a word, and the scene would
        // hold another object than the one written.
        let reads: &[&str] = match kind_name.as_str() {
            "sphere" => &["radius_m"],
            "ellipsoid" => &["radii_m"],
            "box" => &["size_m"],
            "mesh" => &["mesh", "scale"],
            _ if catalog.find_word(&kind_name).is_some() => &["size_m"],
            // An unknown kind is named as such below.
            _ => &["radius_m", "radii_m", "size_m", "mesh", "scale"],
        };
        let given = [
            ("radius_m", o.radius_m.is_some()),
            ("radii_m", o.radii_m.is_some()),
            ("size_m", o.size_m.is_some()),
            ("mesh", o.mesh.is_some()),
            ("scale", o.scale.is_some()),
        ];
        if let Some((name, _)) = given.iter().find(|(n, on)| *on && !reads.contains(n)) {
            return Err(err(
                &field(name),
                format!(
                    "not read for kind '{}', which takes {}",
                    crate::printable::printable(&kind_name),
                    reads.join(" or ")
                ),
            ));
        }
        let (kind, label, hardness, ripeness, color) = match kind_name.as_str() {
            "sphere" | "ellipsoid" | "box" | "mesh" => {
                if o.ripeness.is_some() {
                    return Err(err(
                        &field("ripeness"),
                        format!("only catalog fruits have ripeness stages, not '{kind_name}'"),
                    ));
                }
                let kind = match kind_name.as_str() {
                    "sphere" => ObjectKind::Sphere {
                        radius_m: size("radius_m", need("radius_m", o.radius_m)?)?,
                    },
                    "ellipsoid" => ObjectKind::Ellipsoid {
                        radii_m: need3("radii_m", o.radii_m)?,
                    },
                    "box" => ObjectKind::Box {
                        size_m: need3("size_m", o.size_m)?,
                    },
                    _ => {
                        let rel = o.mesh.as_ref().ok_or_else(|| {
                            err(&field("mesh"), "required for kind 'mesh'".into())
                        })?;
                        let path = base.join(rel);
                        if path.is_dir() {
                            return Err(err(
                                &field("mesh"),
                                format!("'{}' is a directory, not a mesh file", path.display()),
                            ));
                        }
                        // A link looping or leading nowhere is named by `regular` below.
                        if std::fs::symlink_metadata(&path).is_err() {
                            return Err(err(
                                &field("mesh"),
                                format!("mesh file '{}' not found", path.display()),
                            ));
                        }
                        if let Err(e) = crate::text_file::regular(&path) {
                            return Err(err(&field("mesh"), format!("'{}': {e}", path.display())));
                        }
                        ObjectKind::Mesh {
                            path,
                            scale: {
                                let scale = o.scale.unwrap_or(1.0);
                                if !(scale.is_finite()
                                    && (MESH_SCALE[0]..=MESH_SCALE[1]).contains(&scale))
                                {
                                    return Err(err(
                                        &field("scale"),
                                        format!(
                                            "{} is not a mesh unit in metres ({} for millimetres to {})",
                                            short_number(scale),
                                            MESH_SCALE[0] * 10.0,
                                            MESH_SCALE[1]
                                        ),
                                    ));
                                }
                                scale
                            },
                        }
                    }
                };
                let hardness = explicit_hardness.ok_or_else(|| {
                    err(
                        &field("hardness"),
                        format!("required for kind '{kind_name}' (or modulus_mpa)"),
                    )
                })?;
                (
                    kind,
                    o.label.clone().unwrap_or(kind_name.clone()),
                    hardness,
                    None,
                    o.color.unwrap_or(DEFAULT_OBJECT_COLOR),
                )
            }
            _ => {
                let fruit = catalog.find_word(&kind_name).ok_or_else(|| {
                    err(
                        &field("kind"),
                        format!(
                            "unknown kind '{}' (known: sphere, ellipsoid, box, mesh, {})",
                            o.kind,
                            catalog.names().join(", ")
                        ),
                    )
                })?;
                let stage_name = o.ripeness.clone().unwrap_or(fruit.default_stage.clone());
                let stage = fruit.stage(&stage_name).ok_or_else(|| {
                    let known: Vec<_> = fruit.stages.iter().map(|s| s.name.as_str()).collect();
                    err(
                        &field("ripeness"),
                        format!(
                            "unknown ripeness stage '{stage_name}' for {} (known: {})",
                            fruit.name,
                            known.join(", ")
                        ),
                    )
                })?;
                let hardness = explicit_hardness.unwrap_or(Hardness::ModulusMpa(stage.modulus_mpa));
                // The stage the fruit is in follows its stiffness when the scene overrides it.
                let ripeness = fruit.stage_for_modulus(hardness.modulus_mpa()).name.clone();
                let color = o
                    .color
                    .unwrap_or(fruit.stage(&ripeness).map_or(stage.color, |s| s.color));
                let size_m = match o.size_m {
                    Some(size) => need3("size_m", Some(size))?,
                    None => fruit.size_m,
                };
                let kind = ObjectKind::Fruit {
                    name: fruit.name.clone(),
                    shape: fruit.shape,
                    size_m,
                };
                (kind, fruit.name.clone(), hardness, Some(ripeness), color)
            }
        };
        Ok(SceneObject {
            label,
            kind,
            position_m: [x, y],
            yaw_deg,
            hardness,
            ripeness,
            color,
            poisson,
        })
    }
}

/// Objects one scene may have: a crowded table holds a few dozen fruit.
pub const MAX_OBJECTS: usize = 64;
/// An object's radius, radii or sides (m): from a 1 mm berry to a 1 m melon on a table.
pub const OBJECT_SIZE_M: [f64; 2] = [1e-3, 1.0];
/// A table's sides (m).
pub const TABLE_SIZE_M: [f64; 2] = [0.05, 10.0];
/// Mesh units in metres: from 0.1 mm (1e-4) to 10 m.
pub const MESH_SCALE: [f64; 2] = [1e-4, 10.0];

fn check_color(c: &[f64; 3]) -> Result<(), String> {
    if c.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)) {
        Ok(())
    } else {
        Err(format!("must be [r, g, b] in [0, 1], got {c:?}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Scene, SceneError> {
        Scene::parse(text, Path::new("t.toml"), &FruitCatalog::builtin())
    }

    #[test]
    fn a_written_scene_loads_back_to_itself() {
        let s = parse(
            r#"name = "written"
            [camera]
            position_m = [0.1, -0.05, 0.65]
            look_at_m = [0.02, 0.01, 0.0]
            [[objects]]
            kind = "banana"
            position_m = [0.1, -0.05]
            yaw_deg = 33.3
            size_m = [0.2, 0.055, 0.04]
            modulus_mpa = 0.61
            [[objects]]
            kind = "box"
            size_m = [0.04, 0.05, 0.03]
            hardness = "rigid"
            position_m = [-0.1, 0.1]
            label = "block"
            "#,
        )
        .unwrap();
        let back = parse(&s.to_toml()).unwrap();
        assert_eq!(back.objects, s.objects);
        assert_eq!(back.table, s.table);
        assert_eq!(back.intrinsics, s.intrinsics);
        let (a, b) = (back.camera_pose, s.camera_pose);
        assert!(a.position.distance(b.position) < 1e-12);
        assert!(a.rotation.angle_between(b.rotation) < 1e-6);
        // A fruit's own size replaces the catalog's; a bad one names the field.
        let e = parse(
            "name = \"x\"\n[[objects]]\nkind = \"lime\"\nsize_m = [0.05, -1, 0.05]\nposition_m = [0, 0]\n",
        )
        .unwrap_err();
        assert_eq!(e.field, "objects[0].size_m", "{e}");
    }

    #[test]
    fn the_documented_shape_loads() {
        let s = parse(
            r#"name = "demo"
            [camera]
            position_m = [0.0, 0.0, 0.70]
            look_at_m = [0.0, 0.0, 0.0]
            [[objects]]
            kind = "banana"
            position_m = [0.12, -0.05]
            yaw_deg = 30
            ripeness = "ripe"
            [[objects]]
            kind = "sphere"
            radius_m = 0.03
            position_m = [0.0, 0.0]
            hardness = "35A"
            [[objects]]
            kind = "lemon"
            position_m = [-0.1, 0.1]
            modulus_mpa = 0.8
            "#,
        )
        .unwrap();
        assert_eq!(s.objects.len(), 3);
        assert_eq!(s.objects[0].hardness, Hardness::ModulusMpa(0.8));
        assert_eq!(s.objects[1].hardness, Hardness::ShoreA(35.0));
        assert_eq!(s.objects[2].ripeness.as_deref(), Some("ripe"));
    }

    fn error_of(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn bad_fields_are_named() {
        let e = error_of("name = \"x\"\n[[objects]]\nkind = \"pear\"\nposition_m = [0, 0]\n");
        assert!(
            e.starts_with("t.toml: objects[0].kind: unknown kind 'pear'"),
            "{e}"
        );
        let e = error_of(
            "name = \"x\"\n[[objects]]\nkind = \"banana\"\nripeness = \"rotten\"\nposition_m = [0, 0]\n",
        );
        assert!(
            e.contains("objects[0].ripeness: unknown ripeness stage 'rotten'"),
            "{e}"
        );
        // A size the kind does not read: the scene would hold another object than written.
        for (kind, extra, field) in [
            (
                "apple",
                "scale = 0.001",
                "objects[0].scale: not read for kind 'apple'",
            ),
            (
                "sphere",
                "radius_m = 0.02\nsize_m = [1, 1, 1]\nhardness = \"rigid\"",
                "objects[0].size_m",
            ),
            (
                "box",
                "size_m = [0.02, 0.02, 0.02]\nradius_m = 0.5\nhardness = \"rigid\"",
                "objects[0].radius_m",
            ),
        ] {
            let e = error_of(&format!(
                "name = \"x\"\n[[objects]]\nkind = \"{kind}\"\nposition_m = [0, 0]\n{extra}\n"
            ));
            assert!(e.contains(field), "{e}");
        }
        let e = error_of("name = \"x\"\n[[objects]]\nkind = \"banana\"\nposition_m = [nan, 0]\n");
        assert!(e.contains("objects[0].position_m: must be finite"), "{e}");
        let e = error_of("name = \"x\"\n[[objects]]\nkind = \"banana\"\nposition_m = [3.0, 0]\n");
        assert!(
            e.contains("objects[0].position_m") && e.contains("off the table"),
            "{e}"
        );
        let e = error_of(
            "name = \"x\"\n[[objects]]\nkind = \"mesh\"\nmesh = \"nope.obj\"\nhardness = \"40A\"\nposition_m = [0, 0]\n",
        );
        assert!(e.contains("objects[0].mesh: mesh file"), "{e}");
        let e = error_of("name = \"x\"\n[[objects]\nkind = 3\n");
        assert!(
            e.starts_with("t.toml: toml: line 2 (`[[objects]`): "),
            "{e}"
        );
        let e = error_of(
            "name = \"x\"\n[[objects]]\nkind = \"sphere\"\nposition_m = [0, 0]\nhardness = \"40A\"\n",
        );
        assert!(e.contains("objects[0].radius_m: required"), "{e}");
        let e = error_of(
            "name = \"x\"\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\ncolour = [1, 0, 0]\n",
        );
        assert!(e.contains("unknown field `colour`"), "{e}");
        assert!(!e.contains('\n'), "errors are one line: {e}");
    }
}
