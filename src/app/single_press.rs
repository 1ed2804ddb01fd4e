//! One press of the gel into a primitive or a mesh, solved at a chosen fidelity and rendered
//! through a sensor profile: what `tactex press` and the Python package's `Sensor.press`
//! both run, so that the same request gives the same frame bytes through either.

use crate::app::flag_range::FieldError;
use anyhow::{Context, Result, bail};
use glam::{DQuat, DVec2, DVec3};
use image::RgbImage;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;
use tactex_core::hardness::scale::{Hardness, HardnessReport};
use tactex_core::hertz::Elastic;
use tactex_core::press::protocol::PressProtocol;
use tactex_core::tactile::sensor_profile::{ProfileId, SensorProfile};
use tactex_core::tactile::spec::GelSpec;
use tactex_sim::contact::{
    ContactError, ContactProblem, ContactSolution, ContactSolver, Fidelity, GelFields, Grid,
    HeightMap, ObjectSurface, Rect, field_pooling, mesh_top,
};
use tactex_sim::datagen::press_protocol::{PlannedPress, PressSetup, plan_press};
use tactex_sim::mesh::TriMesh;
use tactex_sim::render::gel::{
    CpuRenderer, GelImageFields, GelRenderer, PressFrame, SensorOptics, image_fields,
};

/// What is pressed, in its own frame.
#[derive(Clone, Debug)]
pub enum PressShape {
    Sphere {
        radius_mm: f64,
    },
    /// Full extents X, Y, Z (mm).
    Ellipsoid {
        size_mm: [f64; 3],
    },
    Box {
        size_mm: [f64; 3],
    },
    /// A mesh file pressed at the middle of its top; `scale` turns mesh units into metres.
    Mesh {
        path: PathBuf,
        scale: f64,
    },
    /// A mesh the caller made (vertices in its units, z up; triangles), pressed as a file's
    /// would be; `name` is how errors name it (Python's `mesh`).
    Triangles {
        mesh: TriMesh,
        scale: f64,
        name: String,
    },
    /// A surface the caller computed (Taxim's contract, see `HeightMap`), centred on the
    /// pose: its highest point touches first.
    HeightMap(HeightMap),
}

/// Where the object stands on the pad: its lowest point (a mesh: the middle of its top) at
/// `at_mm` in the pad frame, turned `yaw_deg` about the pressing axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PressPose {
    pub at_mm: [f64; 2],
    pub yaw_deg: f64,
}

impl PressShape {
    pub fn name(&self) -> &'static str {
        match self {
            PressShape::Sphere { .. } => "sphere",
            PressShape::Ellipsoid { .. } => "ellipsoid",
            PressShape::Box { .. } => "box",
            PressShape::Mesh { .. } | PressShape::Triangles { .. } => "mesh",
            PressShape::HeightMap(_) => "height map",
        }
    }

    /// The object's surface over the pad, placed at `pose`.
    pub fn surface(&self, pose: PressPose) -> Result<ObjectSurface> {
        let centre_mm = DVec2::from_array(pose.at_mm);
        let yaw_rad = pose.yaw_deg.to_radians();
        Ok(match self {
            PressShape::Sphere { radius_mm } => ObjectSurface::Sphere {
                radius_mm: *radius_mm,
                centre_mm,
            },
            PressShape::Ellipsoid { size_mm } => ObjectSurface::Ellipsoid {
                semi_axes_mm: DVec3::from_array(*size_mm) / 2.0,
                centre_mm,
                yaw_rad,
            },
            PressShape::Box { size_mm } => ObjectSurface::Box {
                size_mm: DVec3::from_array(*size_mm).truncate(),
                centre_mm,
                yaw_rad,
            },
            PressShape::Mesh { path, scale } => {
                let mesh = tactex_sim::mesh::load(path)?;
                let path = path.display().to_string();
                let named = MeshNames {
                    mesh: &path,
                    flag: &format!("--mesh {path}"),
                    scale: "--mesh-scale",
                };
                placed_mesh(&mesh, named, *scale, pose)?
            }
            PressShape::Triangles { mesh, scale, name } => {
                let named = MeshNames {
                    mesh: name,
                    flag: name,
                    scale: "mesh_scale",
                };
                placed_mesh(mesh, named, *scale, pose)?
            }
            PressShape::HeightMap(map) => ObjectSurface::Mesh(
                map.sheet()?
                    .transformed(DQuat::from_rotation_z(yaw_rad), centre_mm.extend(0.0)),
            ),
        })
    }
}

/// How errors name a mesh: as the mesh itself (its path), as the option that gave it, and
/// the option that sets its unit.
struct MeshNames<'a> {
    mesh: &'a str,
    flag: &'a str,
    scale: &'a str,
}

/// A mesh in its own units, checked as a solid of a table's size, pressed at the middle of
/// its top at `pose`: a file's and a caller's mesh alike.
fn placed_mesh(
    mesh: &TriMesh,
    names: MeshNames,
    scale: f64,
    pose: PressPose,
) -> Result<ObjectSurface> {
    let MeshNames {
        mesh: name,
        flag,
        scale: scale_name,
    } = names;
    mesh.validate(name)?;
    if let Some(size_m) = mesh.size_off_table_m(scale) {
        let [least, most] = tactex_core::scene::OBJECT_SIZE_M;
        // A contact error: bad input, named as the caller named the mesh.
        return Err(ContactError {
            field: flag.to_string(),
            message: format!(
                "{} m across at {scale_name} {}, not a size an object on a table has ({least} to {most} m); set {scale_name} to the mesh's unit in metres",
                tactex_core::printable::short_number(size_m),
                tactex_core::printable::short_number(scale)
            ),
        }
        .into());
    }
    Ok(ObjectSurface::Mesh(
        mesh_top(mesh, scale * 1e3).transformed(
            DQuat::from_rotation_z(pose.yaw_deg.to_radians()),
            DVec2::from_array(pose.at_mm).extend(0.0),
        ),
    ))
}

/// One press: the object, how far past first touch, the physics, and the sensor (its gel
/// and markers already as wanted).
#[derive(Clone, Debug)]
pub struct PressRequest {
    pub shape: PressShape,
    pub pose: PressPose,
    pub hardness: Hardness,
    pub object_poisson: f64,
    /// The sensor's travel past first touch (mm): total approach of gel and object.
    pub depth_mm: f64,
    pub fidelity: Fidelity,
    /// Solver cell (mm); None picks one from the contact's size.
    pub cell_mm: Option<f64>,
    /// Relative pressure change at which the contact solve stops.
    pub tolerance: f64,
    /// Shared: a caller pressing many times through one profile does not copy it.
    pub sensor: Arc<SensorProfile>,
    /// Seed of the rendered frame's camera noise; the no-contact frame takes seed + 1.
    pub seed: u32,
}

#[derive(Serialize)]
pub struct GridReport {
    pub cell_mm: f64,
    pub nx: usize,
    pub ny: usize,
    pub origin_mm: [f64; 2],
}

impl From<&Grid> for GridReport {
    fn from(g: &Grid) -> Self {
        Self {
            cell_mm: g.cell_mm,
            nx: g.nx,
            ny: g.ny,
            origin_mm: [g.origin_mm.x, g.origin_mm.y],
        }
    }
}

#[derive(Serialize)]
pub struct PressReport {
    pub fidelity: String,
    /// The sensor profile (after the gel and marker flags) the press used.
    pub sensor: ProfileId,
    pub shape: String,
    /// Where the object's lowest point stands on the pad (mm, pad frame) and its turn.
    pub at_mm: [f64; 2],
    pub yaw_deg: f64,
    pub depth_mm: f64,
    pub force_n: f64,
    pub contact_radius_mm: f64,
    pub contact_area_mm2: f64,
    pub max_pressure_mpa: f64,
    pub gel_max_indentation_mm: f64,
    pub object_max_indentation_mm: f64,
    pub gel_modulus_mpa: f64,
    pub gel_poisson: f64,
    pub gel_thickness_mm: f64,
    pub object_modulus_mpa: Option<f64>,
    pub object_poisson: f64,
    pub object_shore_a: f64,
    pub object_shore_00: f64,
    pub grid: GridReport,
    pub iterations: usize,
    pub residual: f64,
    pub warnings: Vec<String>,
}

/// A press solved: its figures, and the solution with the solver that can extend its fields.
pub struct SolvedPress {
    pub report: PressReport,
    pub solution: ContactSolution,
    pub solver: ContactSolver,
    pub pad: Rect,
}

impl PressRequest {
    /// Every number of the request within the range `tactex press` states for it, however
    /// the request was built: a program's own `PressRequest` is held to what the CLI's
    /// parsers and `PressOptions` hold theirs to.
    pub fn check(&self) -> Result<(), FieldError> {
        use crate::app::press_options::fields::*;
        match &self.shape {
            PressShape::Sphere { radius_mm } => {
                RADIUS_MM.check(*radius_mm)?;
            }
            PressShape::Ellipsoid { size_mm } | PressShape::Box { size_mm } => {
                for s in size_mm {
                    SIZE_MM.check(*s)?;
                }
            }
            PressShape::Mesh { scale, .. } | PressShape::Triangles { scale, .. } => {
                MESH_SCALE.check(*scale)?;
            }
            PressShape::HeightMap(_) => {}
        }
        for v in self.pose.at_mm {
            AT_MM.check(v)?;
        }
        // On the pad (a contact may still be cut by its edge).
        let [x, y] = self.pose.at_mm;
        let [hw, hh] = self.sensor.spec.pad_size_mm().map(|s| s / 2.0);
        if x.abs() > hw || y.abs() > hh {
            return Err(FieldError::new(
                "at_mm",
                format!(
                    "({x}, {y}) mm is off the pad, which spans X -{hw:.2}..{hw:.2} and Y -{hh:.2}..{hh:.2} mm"
                ),
            ));
        }
        YAW_DEG.check(self.pose.yaw_deg)?;
        if let Hardness::ModulusMpa(e) = self.hardness {
            MODULUS_MPA.check(e)?;
        }
        OBJECT_POISSON.check(self.object_poisson)?;
        DEPTH_MM.check(self.depth_mm)?;
        if let Some(cell) = self.cell_mm {
            GRID_MM.check(cell)?;
        }
        TOLERANCE.check(self.tolerance)?;
        let gel = &self.sensor.spec.gel;
        GEL_THICKNESS_MM.check(gel.thickness_mm)?;
        GEL_MODULUS_MPA.check(gel.modulus_mpa)?;
        Ok(())
    }

    /// Solves the contact and reports its figures.
    pub fn solve(&self) -> Result<SolvedPress> {
        self.solve_with(ContactSolver::new())
    }

    /// As `solve`, with `solver`, whose kernels (one set per grid) carry over from the
    /// presses it solved before: a caller pressing step after step hands it back each time.
    pub fn solve_with(&self, mut solver: ContactSolver) -> Result<SolvedPress> {
        self.check()?;
        let surface = self.shape.surface(self.pose)?;
        let gel = self.sensor.spec.gel;
        let pad = Rect::centred(DVec2::from(self.sensor.spec.pad_size_mm()) / 2.0);
        let problem = ContactProblem {
            surface: &surface,
            object: Elastic {
                modulus_mpa: self.hardness.modulus_mpa(),
                poisson: self.object_poisson,
            },
            gel,
            pad,
            approach_mm: self.depth_mm,
            cell_mm: self.cell_mm,
        };
        solver.settings.tolerance = self.tolerance;
        let solution = solver.solve(&problem, self.fidelity)?;
        // The gel's fields are drawn over the pad at the solver's cell; a contact far smaller
        // than a pixel would need billions of them, so they are pooled into coarser cells
        // (the solve's force and contact are its own), and the report says so.
        let mut warnings = solution.warnings.clone();
        let pool = field_pooling(solution.grid.cell_mm, &pad);
        if pool > 1 {
            warnings.push(format!(
                "the contact is finer than the frame can show: the gel's fields are drawn at {:.4} mm cells, {pool} x {pool} of the solver's {:.5} mm (force and contact are the solver's)",
                solution.grid.cell_mm * pool as f64,
                solution.grid.cell_mm
            ));
        }
        let shown = HardnessReport::from(self.hardness);
        let report = PressReport {
            fidelity: self.fidelity.to_string(),
            sensor: self.sensor.id(),
            shape: self.shape.name().into(),
            at_mm: self.pose.at_mm,
            yaw_deg: self.pose.yaw_deg,
            depth_mm: self.depth_mm,
            force_n: solution.force_n,
            contact_radius_mm: solution.contact_radius_mm,
            contact_area_mm2: solution.contact_area_mm2,
            max_pressure_mpa: solution.max_pressure_mpa,
            gel_max_indentation_mm: solution.gel_max_indentation_mm,
            object_max_indentation_mm: solution.object_max_indentation_mm,
            gel_modulus_mpa: gel.modulus_mpa,
            gel_poisson: gel.poisson,
            gel_thickness_mm: gel.thickness_mm,
            object_modulus_mpa: self.hardness.modulus_mpa(),
            object_poisson: self.object_poisson,
            object_shore_a: shown.shore_a,
            object_shore_00: shown.shore_00,
            grid: (&solution.grid).into(),
            iterations: solution.iterations,
            residual: solution.residual,
            warnings,
        };
        Ok(SolvedPress {
            report,
            solution,
            solver,
            pad,
        })
    }
}

impl PressRequest {
    /// The paper's press protocol on this object: two no-contact frames, a descent in
    /// 0.25 mm steps until the contact criterion fires, then 8 frames from the first
    /// contact frame (`depth_mm` is not used: the protocol decides how far to go). First
    /// touch falls `phase_mm` (0 to 0.25) before a step. Returns the press and its frames,
    /// rendered on the CPU: the no-contact reference first, then the 8 recorded frames.
    pub fn press_sequence(&self, phase_mm: f64) -> Result<(PlannedPress, Vec<RgbImage>)> {
        self.check()?;
        if !(phase_mm.is_finite() && (0.0..0.25).contains(&phase_mm)) {
            return Err(FieldError::new(
                "phase_mm",
                format!(
                    "{} is outside [0, 0.25): first touch falls within one 0.25 mm step",
                    crate::app::flag_range::show(phase_mm)
                ),
            )
            .into());
        }
        let surface = self.shape.surface(self.pose)?;
        let optics = SensorOptics::for_profile(&self.sensor);
        let setup = PressSetup {
            surface: &surface,
            object: Elastic {
                modulus_mpa: self.hardness.modulus_mpa(),
                poisson: self.object_poisson,
            },
            gel: self.sensor.spec.gel,
            fidelity: self.fidelity,
            optics: &optics,
            phase_mm,
            cell_mm: self.cell_mm,
            seed: self.seed,
        };
        let mut solver = ContactSolver::new();
        solver.settings.tolerance = self.tolerance;
        let press = plan_press(&mut solver, &setup, &PressProtocol::default())?;
        let frames = press.render(&mut CpuRenderer, &optics)?;
        Ok((press, frames))
    }
}

impl SolvedPress {
    /// The pressed frame (seed) and a no-contact frame (seed + 1, its own camera noise, as a
    /// real one taken before the press would have) through `renderer`.
    pub fn render(
        &mut self,
        request: &PressRequest,
        renderer: &mut dyn GelRenderer,
    ) -> Result<(RgbImage, RgbImage)> {
        let optics = SensorOptics::for_profile(&request.sensor);
        let fields = self.image_fields(&request.sensor.spec.gel, &optics);
        let flat = GelImageFields::flat(optics.width, optics.height);
        let mut frames = renderer.render_batch(
            &optics,
            &[
                PressFrame {
                    fields: &fields,
                    seed: request.seed,
                },
                PressFrame {
                    fields: &flat,
                    seed: request.seed.wrapping_add(1),
                },
            ],
        )?;
        let reference = frames.pop().context("the renderer returned no frames")?;
        let frame = frames.pop().context("the renderer returned one frame")?;
        Ok((frame, reference))
    }

    /// What the frame is drawn from: the gel's fields at the frame's pixels.
    pub fn image_fields(&mut self, gel: &GelSpec, optics: &SensorOptics) -> GelImageFields {
        image_fields(&mut self.solver, &self.solution, gel, optics)
    }

    /// The gel's displacement over the whole pad, at the solver's cell unless that would
    /// exceed 1024 cells a side (then over the solver grid alone).
    pub fn pad_fields(&mut self) -> GelFields {
        let cells = self.pad.size().max_element() / self.solution.grid.cell_mm;
        if cells <= 1024.0 {
            self.solver.fields_over(&self.solution, &self.pad)
        } else {
            self.solution.gel.clone()
        }
    }
}

/// A marker grid given as COLSxROWS ("9x7"), checked: 1 to 10000 markers, or 0x0 for a gel
/// without markers (as a profile calibrated from an unmarked gel has).
pub fn parse_marker_grid(text: &str) -> Result<(u32, u32)> {
    let (cols, rows) = text
        .split_once(['x', 'X'])
        .and_then(|(c, r)| Some((c.trim().parse::<u32>().ok()?, r.trim().parse::<u32>().ok()?)))
        .with_context(|| format!("'{text}' is not COLSxROWS (e.g. 9x7, 11x9)"))?;
    let markers = u64::from(cols) * u64::from(rows);
    if (cols, rows) != (0, 0) && (markers == 0 || markers > 10_000) {
        bail!(
            "{cols}x{rows} is {markers} markers; a gel has 1 to 10000 (e.g. 9x7, 11x9), or 0x0 for none"
        );
    }
    Ok((cols, rows))
}

#[cfg(test)]
mod tests {
    use super::parse_marker_grid;

    #[test]
    fn a_marker_grid_of_0x0_is_a_gel_without_markers_and_a_half_empty_one_is_refused() {
        assert_eq!(parse_marker_grid("0x0").unwrap(), (0, 0));
        assert_eq!(parse_marker_grid("11X9").unwrap(), (11, 9));
        for bad in ["0x7", "9x0", "1000x1000", "9by7"] {
            assert!(parse_marker_grid(bad).is_err(), "{bad}");
        }
    }
}
