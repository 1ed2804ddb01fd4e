//! One press as a caller describes it, the CLI's `tactex press` flags and Python's
//! `Sensor.press` keywords alike: the object by shape name and sizes (or the caller's own
//! mesh or height map), its hardness as text or a modulus, the sensor's gel and markers
//! overridden. [`PressOptions::request`] checks every field against its [`Field`] (the
//! ranges the CLI's parsers use) and makes the [`PressRequest`] the solver runs; a mistake
//! is a [`FieldError`] naming the field, which each front end says in its caller's words.

use crate::app::flag_range::{Field, FieldError, flag};
use crate::app::single_press::{PressPose, PressRequest, PressShape, parse_marker_grid};
use std::path::PathBuf;
use std::str::FromStr;
use std::sync::Arc;
use tactex_core::hardness::scale::Hardness;
use tactex_core::tactile::sensor_profile::{MIN_GEL_THICKNESS_MM, SensorProfile};
use tactex_sim::contact::Fidelity;

/// Every number of a press and its range: what `tactex press --help` states and what
/// [`PressRequest::check`] holds a request to, however it was built.
pub mod fields {
    use super::{Field, MIN_GEL_THICKNESS_MM};
    pub const RADIUS_MM: Field = Field::above("radius_mm", 0.0, 500.0);
    pub const SIZE_MM: Field = Field::above("size_mm", 0.0, 1000.0);
    pub const YAW_DEG: Field = Field::within("yaw_deg", -360.0, 360.0);
    pub const AT_MM: Field = Field::within("at_mm", -100.0, 100.0);
    pub const MESH_SCALE: Field = Field::above("mesh_scale", 0.0, 1000.0);
    pub const MODULUS_MPA: Field = Field::above("modulus_mpa", 0.0, 1e6);
    pub const OBJECT_POISSON: Field = Field::within("object_poisson", 0.0, 0.5);
    pub const DEPTH_MM: Field = Field::within("depth_mm", 0.0, 30.0);
    pub const GRID_MM: Field = Field::within("grid_mm", 0.02, 5.0);
    pub const TOLERANCE: Field = Field::within("tolerance", 1e-12, 0.5);
    pub const GEL_THICKNESS_MM: Field =
        Field::within("gel_thickness_mm", MIN_GEL_THICKNESS_MM, 50.0);
    pub const GEL_MODULUS_MPA: Field = Field::within("gel_modulus_mpa", 0.01, 50.0);
    pub const MARKER_PITCH_MM: Field = Field::above("marker_pitch_mm", 0.0, 20.0);
}

/// The object families a press takes by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShapeKind {
    #[default]
    Sphere,
    Ellipsoid,
    Box,
    Mesh,
}

impl ShapeKind {
    pub const ALL: [ShapeKind; 4] = [Self::Sphere, Self::Ellipsoid, Self::Box, Self::Mesh];
    pub const NAMES: [&'static str; 4] = ["sphere", "ellipsoid", "box", "mesh"];

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl FromStr for ShapeKind {
    type Err = FieldError;
    fn from_str(s: &str) -> Result<Self, FieldError> {
        let wanted = s.trim().to_ascii_lowercase();
        Self::ALL
            .into_iter()
            .find(|k| k.name() == wanted)
            .ok_or_else(|| {
                FieldError::new(
                    "shape",
                    format!("unknown shape {s:?} (use {})", Self::NAMES.join(", ")),
                )
            })
    }
}

/// Sphere radius when none is given (mm).
pub const DEFAULT_RADIUS_MM: f64 = 10.0;

/// One press in the caller's terms; `Default` is the CLI's defaults (a 10 mm sphere at the
/// pad's centre, rigid-free: a hardness must still be given).
#[derive(Clone, Debug)]
pub struct PressOptions {
    pub shape: ShapeKind,
    pub radius_mm: Option<f64>,
    /// Ellipsoid or box full extents X, Y, Z (mm); default a cube or ball of 2 radii.
    pub size_mm: Option<Vec<f64>>,
    pub mesh: Option<PathBuf>,
    pub mesh_scale: Option<f64>,
    /// The caller's own object (a mesh from arrays, a height map), pressed in place of a
    /// named shape; the shape's size fields are then not read.
    pub object: Option<PressShape>,
    /// Where on the pad the object stands, X, Y (mm, pad frame); default the centre.
    pub at_mm: Option<Vec<f64>>,
    pub yaw_deg: f64,
    /// Hardness as scene files write it ("35A", "55 00", "rigid"), or `modulus_mpa`.
    pub hardness: Option<String>,
    pub modulus_mpa: Option<f64>,
    pub object_poisson: f64,
    pub depth_mm: f64,
    pub fidelity: String,
    pub grid_mm: Option<f64>,
    pub tolerance: f64,
    pub gel_thickness_mm: Option<f64>,
    pub gel_modulus_mpa: Option<f64>,
    /// COLSxROWS ("9x7"), 0x0 for none; default the profile's.
    pub marker_grid: Option<String>,
    pub marker_pitch_mm: Option<f64>,
    pub seed: u32,
}

impl Default for PressOptions {
    fn default() -> Self {
        Self {
            shape: ShapeKind::Sphere,
            radius_mm: None,
            size_mm: None,
            mesh: None,
            mesh_scale: None,
            object: None,
            at_mm: None,
            yaw_deg: 0.0,
            hardness: None,
            modulus_mpa: None,
            object_poisson: 0.45,
            depth_mm: 0.0,
            fidelity: "layer".into(),
            grid_mm: None,
            tolerance: 1e-6,
            gel_thickness_mm: None,
            gel_modulus_mpa: None,
            marker_grid: None,
            marker_pitch_mm: None,
            seed: 0,
        }
    }
}

fn optional(field: Field, v: Option<f64>) -> Result<Option<f64>, FieldError> {
    v.map(|v| field.check(v)).transpose()
}

impl PressOptions {
    /// The press these options describe through `sensor`, every field checked; the
    /// profile is copied only when the options change its gel or markers.
    pub fn request(&self, mut sensor: Arc<SensorProfile>) -> Result<PressRequest, FieldError> {
        use fields::*;
        // Every number first, as the CLI's parser reads them before anything else: a NaN
        // depth is named even when the hardness is missing too.
        optional(RADIUS_MM, self.radius_mm)?;
        YAW_DEG.check(self.yaw_deg)?;
        optional(MODULUS_MPA, self.modulus_mpa)?;
        OBJECT_POISSON.check(self.object_poisson)?;
        DEPTH_MM.check(self.depth_mm)?;
        optional(GRID_MM, self.grid_mm)?;
        TOLERANCE.check(self.tolerance)?;
        let fidelity: Fidelity = self
            .fidelity
            .parse()
            .map_err(|e: String| FieldError::new("fidelity", e))?;
        let shape = self.shape()?;
        let hardness = self.hardness()?;
        if let Some(grid) = &self.marker_grid {
            let (cols, rows) = parse_marker_grid(grid)
                .map_err(|e| FieldError::new("marker_grid", e.to_string()))?;
            let m = &mut Arc::make_mut(&mut sensor).spec.markers;
            m.cols = cols;
            m.rows = rows;
        }
        if let Some(pitch) = optional(MARKER_PITCH_MM, self.marker_pitch_mm)? {
            let spec = &sensor.spec;
            let m = &spec.markers;
            let bad = |problem: String| Err(FieldError::new("marker_pitch_mm", problem));
            if m.cols * m.rows == 0 {
                return bad(format!(
                    "the gel has no markers ({} 0x0 or the profile's)",
                    flag("marker_grid")
                ));
            }
            let pad = spec.pad_size_mm();
            let span = [f64::from(m.cols - 1) * pitch, f64::from(m.rows - 1) * pitch];
            if span[0] > pad[0] || span[1] > pad[1] {
                return bad(format!(
                    "{pitch} mm: a {} x {} grid spans {:.1} x {:.1} mm, past the {:.1} x {:.1} mm pad",
                    m.cols, m.rows, span[0], span[1], pad[0], pad[1]
                ));
            }
            // Dots wider than their spacing would merge into one dark gel, not a grid.
            if pitch <= 2.0 * m.radius_mm {
                return bad(format!(
                    "{pitch} mm is not over the markers' diameter ({:.3} mm); they would overlap",
                    2.0 * m.radius_mm
                ));
            }
            Arc::make_mut(&mut sensor).spec.markers.pitch_mm = pitch;
        }
        if let Some(t) = optional(GEL_THICKNESS_MM, self.gel_thickness_mm)? {
            Arc::make_mut(&mut sensor).spec.gel.thickness_mm = t;
        }
        if let Some(e) = optional(GEL_MODULUS_MPA, self.gel_modulus_mpa)? {
            Arc::make_mut(&mut sensor).spec.gel.modulus_mpa = e;
        }
        let pose = PressPose {
            at_mm: self.at_mm()?,
            yaw_deg: self.yaw_deg,
        };
        let request = PressRequest {
            shape,
            pose,
            hardness,
            object_poisson: self.object_poisson,
            depth_mm: self.depth_mm,
            fidelity,
            cell_mm: self.grid_mm,
            tolerance: self.tolerance,
            sensor,
            seed: self.seed,
        };
        request.check()?;
        Ok(request)
    }

    fn shape(&self) -> Result<PressShape, FieldError> {
        use fields::*;
        if let Some(object) = &self.object {
            let given = [
                ("radius_mm", self.radius_mm.is_some()),
                ("size_mm", self.size_mm.is_some()),
                ("mesh", self.mesh.is_some()),
            ];
            if let Some((field, _)) = given.iter().find(|(_, on)| *on) {
                return Err(FieldError::new(
                    field,
                    format!("not read: the object is the caller's own {}", object.name()),
                ));
            }
            if let PressShape::Triangles { scale, .. } = object {
                MESH_SCALE.check(*scale)?;
            }
            return Ok(object.clone());
        }
        self.refuse_unused_fields()?;
        let radius_mm = optional(RADIUS_MM, self.radius_mm)?.unwrap_or(DEFAULT_RADIUS_MM);
        let size = || -> Result<[f64; 3], FieldError> {
            match &self.size_mm {
                Some(v) => {
                    let [x, y, z] = v[..] else {
                        return Err(FieldError::new(
                            "size_mm",
                            format!("give three sizes X,Y,Z in mm, got {}", v.len()),
                        ));
                    };
                    Ok([SIZE_MM.check(x)?, SIZE_MM.check(y)?, SIZE_MM.check(z)?])
                }
                None => Ok([2.0 * radius_mm; 3]),
            }
        };
        Ok(match self.shape {
            ShapeKind::Sphere => PressShape::Sphere { radius_mm },
            ShapeKind::Ellipsoid => PressShape::Ellipsoid { size_mm: size()? },
            ShapeKind::Box => PressShape::Box { size_mm: size()? },
            ShapeKind::Mesh => PressShape::Mesh {
                path: self.mesh.clone().ok_or_else(|| {
                    FieldError::new("mesh", format!("{} mesh needs a mesh file", flag("shape")))
                })?,
                scale: optional(MESH_SCALE, self.mesh_scale)?.unwrap_or(1.0),
            },
        })
    }

    /// A size the chosen shape does not read would be dropped without a word, and the user
    /// would believe the press was of the object they described.
    fn refuse_unused_fields(&self) -> Result<(), FieldError> {
        let given = [
            ("radius_mm", self.radius_mm.is_some()),
            ("size_mm", self.size_mm.is_some()),
            ("mesh", self.mesh.is_some()),
            ("mesh_scale", self.mesh_scale.is_some()),
        ];
        let used: &[&str] = match self.shape {
            ShapeKind::Sphere => &["radius_mm"],
            ShapeKind::Ellipsoid | ShapeKind::Box if self.size_mm.is_some() => &["size_mm"],
            ShapeKind::Ellipsoid | ShapeKind::Box => &["radius_mm", "size_mm"],
            ShapeKind::Mesh => &["mesh", "mesh_scale"],
        };
        match given.iter().find(|(f, on)| *on && !used.contains(f)) {
            Some((field, _)) => Err(FieldError::new(
                field,
                format!(
                    "not read for {} {}, which takes {}",
                    flag("shape"),
                    self.shape.name(),
                    used.iter()
                        .map(|f| flag(f))
                        .collect::<Vec<_>>()
                        .join(" or ")
                ),
            )),
            None => Ok(()),
        }
    }

    fn hardness(&self) -> Result<Hardness, FieldError> {
        match (&self.hardness, self.modulus_mpa) {
            (Some(_), Some(_)) => Err(FieldError::new(
                "hardness",
                format!("give the hardness or {}, not both", flag("modulus_mpa")),
            )),
            (Some(text), None) => {
                Hardness::parse(text).map_err(|e| FieldError::new("hardness", e.to_string()))
            }
            (None, Some(e)) => Ok(Hardness::ModulusMpa(fields::MODULUS_MPA.check(e)?)),
            (None, None) => Err(FieldError::new(
                "hardness",
                format!(
                    "give the object's hardness (e.g. \"35A\", \"rigid\") or {}",
                    flag("modulus_mpa")
                ),
            )),
        }
    }

    /// `at_mm` as X, Y.
    fn at_mm(&self) -> Result<[f64; 2], FieldError> {
        let Some(at) = &self.at_mm else {
            return Ok([0.0, 0.0]);
        };
        let bad = |problem: String| Err(FieldError::new("at_mm", problem));
        let [x, y] = at[..] else {
            return bad(format!("give X,Y in mm, got {} values", at.len()));
        };
        // Its range and whether it lies on the pad: `PressRequest::check`.
        Ok([x, y])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options() -> PressOptions {
        PressOptions {
            hardness: Some("35A".into()),
            depth_mm: 1.0,
            ..PressOptions::default()
        }
    }

    fn field_of(o: &PressOptions) -> String {
        o.request(Arc::new(SensorProfile::gelsight_mini()))
            .unwrap_err()
            .field
    }

    #[test]
    fn a_press_built_in_code_is_held_to_the_ranges_the_cli_states() {
        assert!(
            options()
                .request(Arc::new(SensorProfile::gelsight_mini()))
                .is_ok()
        );
        let nan = PressOptions {
            depth_mm: f64::NAN,
            ..options()
        };
        let e = nan
            .request(Arc::new(SensorProfile::gelsight_mini()))
            .unwrap_err();
        assert_eq!(e.field, "depth_mm");
        assert_eq!(e.to_string(), "--depth-mm: NaN is outside [0, 30]");
        let cases = [
            (
                PressOptions {
                    radius_mm: Some(-1.0),
                    ..options()
                },
                "radius_mm",
            ),
            (
                PressOptions {
                    yaw_deg: f64::INFINITY,
                    ..options()
                },
                "yaw_deg",
            ),
            (
                PressOptions {
                    object_poisson: 0.6,
                    ..options()
                },
                "object_poisson",
            ),
            (
                PressOptions {
                    tolerance: 0.0,
                    ..options()
                },
                "tolerance",
            ),
            (
                PressOptions {
                    grid_mm: Some(1e300),
                    ..options()
                },
                "grid_mm",
            ),
            (
                PressOptions {
                    gel_modulus_mpa: Some(0.0),
                    ..options()
                },
                "gel_modulus_mpa",
            ),
            (
                PressOptions {
                    at_mm: Some(vec![20.0, 0.0]),
                    ..options()
                },
                "at_mm",
            ),
            (
                PressOptions {
                    at_mm: Some(vec![1.0]),
                    ..options()
                },
                "at_mm",
            ),
            (
                PressOptions {
                    fidelity: "fem".into(),
                    ..options()
                },
                "fidelity",
            ),
            (
                PressOptions {
                    modulus_mpa: Some(1.0),
                    ..options()
                },
                "hardness",
            ),
            (
                PressOptions {
                    hardness: Some("soft".into()),
                    ..options()
                },
                "hardness",
            ),
            (
                PressOptions {
                    size_mm: Some(vec![1.0, 2.0, 3.0]),
                    ..options()
                },
                "size_mm",
            ),
            (
                PressOptions {
                    marker_grid: Some("9by7".into()),
                    ..options()
                },
                "marker_grid",
            ),
            (
                PressOptions {
                    marker_pitch_mm: Some(0.01),
                    ..options()
                },
                "marker_pitch_mm",
            ),
        ];
        for (o, field) in cases {
            assert_eq!(field_of(&o), field, "{o:?}");
        }
    }

    #[test]
    fn every_shape_name_reads_back_and_a_wrong_one_lists_them() {
        for k in ShapeKind::ALL {
            assert_eq!(k.name().parse::<ShapeKind>(), Ok(k));
        }
        let e = "cube".parse::<ShapeKind>().unwrap_err();
        assert!(e.problem.contains("sphere, ellipsoid, box, mesh"), "{e}");
    }
}
