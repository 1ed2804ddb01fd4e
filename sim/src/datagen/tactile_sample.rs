//! Randomised presses for synthetic pretraining data: an object (primitive, catalog fruit or
//! random blob) of any hardness from the soft end of Shore 00 to the hard end of Shore A,
//! placed under the pad with the paper's pose jitter, pressed by a sensor whose gel, lighting,
//! markers and noise are randomised. Each sample is drawn from (seed, index, attempt) alone, so
//! any shard of a data set can be generated anywhere, in any order.

use crate::contact::{ContactSolver, Fidelity, ObjectSurface, mesh_top};
use crate::datagen::press_protocol::{PlannedPress, PressError, PressSetup, plan_press};
use crate::mesh::{self, Lobe};
use crate::render::gel::SensorOptics;
use glam::{DQuat, DVec2, DVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::hardness::scale::shore_a_to_modulus_mpa;
use tactex_core::hardness::scale::{
    modulus_to_shore_00, modulus_to_shore_a, shore_00_to_modulus_mpa,
};
use tactex_core::hertz::Elastic;
use tactex_core::press::protocol::PressProtocol;
use tactex_core::tactile::photometric::PhotometricModel;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_core::tactile::spec::{GelSpec, TactileSpec};

/// The kinds of object a data set draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeFamily {
    Sphere,
    Ellipsoid,
    Box,
    Fruit,
    Blob,
}

impl ShapeFamily {
    pub const ALL: [ShapeFamily; 5] = [
        ShapeFamily::Sphere,
        ShapeFamily::Ellipsoid,
        ShapeFamily::Box,
        ShapeFamily::Fruit,
        ShapeFamily::Blob,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            ShapeFamily::Sphere => "sphere",
            ShapeFamily::Ellipsoid => "ellipsoid",
            ShapeFamily::Box => "box",
            ShapeFamily::Fruit => "fruit",
            ShapeFamily::Blob => "blob",
        }
    }
}

impl fmt::Display for ShapeFamily {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ShapeFamily {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        ShapeFamily::ALL
            .into_iter()
            .find(|f| f.name() == s.trim().to_ascii_lowercase())
            .ok_or_else(|| {
                format!("unknown shape family {s:?} (use sphere, ellipsoid, box, fruit or blob)")
            })
    }
}

/// The object's shape as drawn (mm), enough to rebuild it.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ShapeDraw {
    Sphere {
        radius_mm: f64,
    },
    Ellipsoid {
        semi_axes_mm: [f64; 3],
    },
    Box {
        footprint_mm: [f64; 2],
    },
    Fruit {
        fruit: String,
        size_mm: [f64; 3],
    },
    Blob {
        size_mm: [f64; 3],
        /// (l, m, amplitude, phase_theta, phase_phi) of each lobe.
        lobes: Vec<[f64; 5]>,
    },
}

/// The randomised sensor: the data set's profile with its gel, lights, markers, exposure,
/// noise and vignetting jittered.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SensorDraw {
    /// The profile drawn around (its name and hash are the data set's).
    #[serde(skip)]
    pub base: Arc<SensorProfile>,
    pub gel: GelSpec,
    pub lighting: PhotometricModel,
    /// Per-channel scale of the background (exposure and white balance).
    pub background_gain: [f64; 3],
    pub marker_grid: [u32; 2],
    pub marker_pitch_mm: f64,
    pub marker_radius_mm: f64,
    pub noise_sigma: f64,
    pub vignette: f64,
}

impl SensorDraw {
    /// The nominal GelSight Mini, unrandomised: the sensor of a lab's validation run.
    pub fn nominal() -> Self {
        Self::of(Arc::new(SensorProfile::gelsight_mini()))
    }

    /// `profile` itself, unrandomised.
    pub fn of(profile: Arc<SensorProfile>) -> Self {
        let spec = &profile.spec;
        Self {
            gel: spec.gel,
            lighting: spec.photometric,
            background_gain: [1.0; 3],
            marker_grid: [spec.markers.cols, spec.markers.rows],
            marker_pitch_mm: spec.markers.pitch_mm,
            marker_radius_mm: spec.markers.radius_mm,
            noise_sigma: profile.noise_sigma_grey,
            vignette: profile.vignette,
            base: profile,
        }
    }
}

/// One randomised press.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleDraw {
    pub index: u64,
    pub attempt: u32,
    pub family: ShapeFamily,
    pub shape: ShapeDraw,
    pub modulus_mpa: f64,
    pub shore_a: f64,
    pub shore_00: f64,
    pub object_poisson: f64,
    /// Where the object's top sits in the pad frame (mm) and its turn (degrees).
    pub offset_mm: [f64; 2],
    pub yaw_deg: f64,
    pub fidelity: Fidelity,
    pub sensor: SensorDraw,
    /// Where first touch falls between two press steps (mm).
    pub phase_mm: f64,
    /// Seed of the frames' camera noise.
    pub noise_seed: u32,
}

/// What a data set draws from.
#[derive(Clone, Debug)]
pub struct SampleSpace {
    pub families: Vec<ShapeFamily>,
    pub fidelity: Fidelity,
    /// Hardness range as moduli (MPa), drawn log-uniformly.
    pub modulus_mpa: [f64; 2],
    /// Pose jitter: offsets within +-`offset_mm`, yaw in [0, `yaw_max_deg`].
    pub offset_mm: f64,
    pub yaw_max_deg: f64,
    pub step_mm: f64,
    /// The sensor the draws jitter around.
    pub sensor: Arc<SensorProfile>,
    /// Marker grids drawn from (cols, rows): the profile's own for a user's sensor; the
    /// stock data sets also print 11 x 9, common on other gels.
    pub marker_grids: Vec<[u32; 2]>,
}

impl Default for SampleSpace {
    /// Every family at the `layer` level, Shore 00 10 to Shore A 90, the paper's jitter
    /// (x-y within +-5 mm, yaw 0-45 degrees) and step (0.25 mm).
    fn default() -> Self {
        Self {
            families: ShapeFamily::ALL.to_vec(),
            fidelity: Fidelity::Layer,
            modulus_mpa: [
                shore_00_to_modulus_mpa(10.0).expect("finite"),
                shore_a_to_modulus_mpa(90.0).expect("finite"),
            ],
            offset_mm: 5.0,
            yaw_max_deg: 45.0,
            step_mm: 0.25,
            sensor: Arc::new(SensorProfile::gelsight_mini()),
            marker_grids: vec![[9, 7], [11, 9]],
        }
    }
}

impl SampleSpace {
    /// Draws around `profile`: its marker grid only.
    pub fn around(self, profile: SensorProfile) -> Self {
        let grid = [profile.spec.markers.cols, profile.spec.markers.rows];
        Self {
            sensor: Arc::new(profile),
            marker_grids: vec![grid],
            ..self
        }
    }
}

/// The stream a sample's draws come from: the data set's seed, the sample's index and the
/// attempt (a redraw after a press that found no contact) mixed into one ChaCha seed.
fn sample_rng(seed: u64, index: u64, attempt: u32) -> ChaCha8Rng {
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    key[8..16].copy_from_slice(&index.to_le_bytes());
    key[16..20].copy_from_slice(&attempt.to_le_bytes());
    key[20..32].copy_from_slice(b"tactex-press");
    ChaCha8Rng::from_seed(key)
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (rng.random_range(lo.ln()..=hi.ln())).exp()
}

/// Draws a sample gets before its index is given up: a draw whose press never shows
/// contact (a very soft object touched off-centre) is redrawn.
pub const MAX_DRAWS: u32 = 8;

/// Plans the press of `draw(0)`, and of `draw(1)`, `draw(2)`, ... while a press finds no
/// contact, up to `MAX_DRAWS` draws.
pub fn press_with_redraws(
    solver: &mut ContactSolver,
    catalog: &FruitCatalog,
    protocol: &PressProtocol,
    draw: impl Fn(u32) -> SampleDraw,
) -> Result<(SampleDraw, PlannedPress), PressError> {
    let mut last = None;
    for attempt in 0..MAX_DRAWS {
        let sample = draw(attempt);
        match sample.plan_press(solver, catalog, protocol) {
            Ok(press) => return Ok((sample, press)),
            Err(e @ PressError::NoContact { .. }) => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.expect("at least one draw"))
}

impl SampleSpace {
    /// Draws sample `index` and plans its press at `step_mm`, redrawing (attempt 1, 2, ...)
    /// when the press finds no contact.
    pub fn press(
        &self,
        solver: &mut ContactSolver,
        catalog: &FruitCatalog,
        seed: u64,
        index: u64,
    ) -> Result<(SampleDraw, PlannedPress), PressError> {
        let protocol = PressProtocol {
            step_mm: self.step_mm,
            ..PressProtocol::default()
        };
        press_with_redraws(solver, catalog, &protocol, |attempt| {
            self.draw(catalog, seed, index, attempt)
        })
    }

    pub fn draw(&self, catalog: &FruitCatalog, seed: u64, index: u64, attempt: u32) -> SampleDraw {
        let mut rng = sample_rng(seed, index, attempt);
        let family = self.families[rng.random_range(0..self.families.len())];
        let shape = match family {
            ShapeFamily::Sphere => ShapeDraw::Sphere {
                radius_mm: log_uniform(&mut rng, 3.0, 60.0),
            },
            ShapeFamily::Ellipsoid => ShapeDraw::Ellipsoid {
                semi_axes_mm: [
                    log_uniform(&mut rng, 4.0, 60.0),
                    log_uniform(&mut rng, 4.0, 60.0),
                    log_uniform(&mut rng, 4.0, 40.0),
                ],
            },
            ShapeFamily::Box => ShapeDraw::Box {
                footprint_mm: [
                    log_uniform(&mut rng, 2.0, 25.0),
                    log_uniform(&mut rng, 2.0, 25.0),
                ],
            },
            ShapeFamily::Fruit => {
                let names = catalog.names();
                let fruit = catalog
                    .get(names[rng.random_range(0..names.len())])
                    .expect("a catalog name");
                let scale = rng.random_range(0.9..1.1);
                ShapeDraw::Fruit {
                    fruit: fruit.name.clone(),
                    size_mm: fruit.size_m.map(|v| v * 1e3 * scale),
                }
            }
            ShapeFamily::Blob => {
                let lobes = (0..rng.random_range(2..=4))
                    .map(|_| {
                        [
                            rng.random_range(1..=4) as f64,
                            rng.random_range(1..=4) as f64,
                            rng.random_range(-0.2..0.2),
                            rng.random_range(0.0..std::f64::consts::TAU),
                            rng.random_range(0.0..std::f64::consts::TAU),
                        ]
                    })
                    .collect();
                ShapeDraw::Blob {
                    size_mm: [
                        log_uniform(&mut rng, 20.0, 120.0),
                        log_uniform(&mut rng, 20.0, 90.0),
                        log_uniform(&mut rng, 15.0, 80.0),
                    ],
                    lobes,
                }
            }
        };
        let modulus_mpa = log_uniform(&mut rng, self.modulus_mpa[0], self.modulus_mpa[1]);
        let object_poisson = rng.random_range(0.3..0.49);
        let offset_mm = [
            rng.random_range(-self.offset_mm..=self.offset_mm),
            rng.random_range(-self.offset_mm..=self.offset_mm),
        ];
        let yaw_deg = rng.random_range(0.0..=self.yaw_max_deg);

        // Around the profile's gel (the GelSight Mini's: E ~ 0.15-0.45 MPa, ~4 mm thick).
        let base = &self.sensor;
        let g = base.spec.gel;
        let gel = GelSpec {
            modulus_mpa: rng.random_range(0.5 * g.modulus_mpa..1.5 * g.modulus_mpa),
            poisson: g.poisson,
            // On a 0.05 mm ladder: the layer model's tables are cached per thickness.
            thickness_mm: (rng.random_range(g.thickness_mm - 0.5..g.thickness_mm + 0.5) / 0.05)
                .round()
                .max(tactex_core::tactile::sensor_profile::MIN_GEL_THICKNESS_MM / 0.05)
                * 0.05,
        };
        // The lights turned together and raised or lowered together.
        let lift = rng.random_range(-10f64..10.0).to_radians();
        let turn = rng.random_range(-15f64..15.0).to_radians();
        let l = base.spec.photometric;
        let lighting = PhotometricModel {
            lights: l.lights.map(|d| {
                let azimuth = d.y.atan2(d.x) + turn;
                let elevation = (d.z.clamp(-1.0, 1.0).asin() + lift)
                    .clamp(5f64.to_radians(), 85f64.to_radians());
                DVec3::new(
                    azimuth.cos() * elevation.cos(),
                    azimuth.sin() * elevation.cos(),
                    elevation.sin(),
                )
            }),
            ambient: (l.ambient + rng.random_range(-0.1..0.1)).max(0.0),
            gain: l.gain * rng.random_range(0.8..1.2),
        };
        let m = base.spec.markers;
        let grid = self
            .marker_grids
            .get(rng.random_range(0..self.marker_grids.len().max(1)))
            .copied()
            .unwrap_or([m.cols, m.rows]);
        let vignette = rng.random_range(-0.15..0.15);
        let sensor = SensorDraw {
            base: base.clone(),
            gel,
            lighting,
            background_gain: std::array::from_fn(|_| rng.random_range(0.9..1.1)),
            marker_grid: grid,
            marker_pitch_mm: m.pitch_mm * rng.random_range(0.8..1.1),
            marker_radius_mm: m.radius_mm * rng.random_range(0.8..1.2),
            noise_sigma: base.noise_sigma_grey * rng.random_range(0.6..3.0),
            // A real background carries its own vignetting: none is added to it.
            vignette: if base.vignette > 0.0 {
                (base.vignette + vignette).clamp(0.0, 1.0)
            } else {
                0.0
            },
        };
        SampleDraw {
            index,
            attempt,
            family,
            shape,
            modulus_mpa,
            shore_a: modulus_to_shore_a(modulus_mpa),
            shore_00: modulus_to_shore_00(modulus_mpa),
            object_poisson,
            offset_mm,
            yaw_deg,
            fidelity: self.fidelity,
            sensor,
            phase_mm: rng.random_range(0.0..self.step_mm),
            noise_seed: rng.random(),
        }
    }
}

/// Deepest the pad can reach into a sample (mm): the protocol's search plus its frames, with
/// room to spare.
const REACH_MM: f64 = 12.0;

/// The triangles the pad can touch: those with a corner above the pad (plus a margin) and
/// within its reach. Rasterising the rest on every solve would only cost time.
fn near_the_pad(mesh: &mesh::TriMesh, pad_mm: [f64; 2]) -> mesh::TriMesh {
    let half = DVec2::from(pad_mm) / 2.0 + DVec2::splat(REACH_MM);
    let keep: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| {
            let v = t.map(|i| mesh.vertices[i as usize]);
            let lo = v[0].min(v[1]).min(v[2]);
            let hi = v[0].max(v[1]).max(v[2]);
            lo.z <= REACH_MM
                && lo.x <= half.x
                && hi.x >= -half.x
                && lo.y <= half.y
                && hi.y >= -half.y
        })
        .copied()
        .collect();
    mesh::TriMesh {
        vertices: mesh.vertices.clone(),
        triangles: keep,
    }
}

/// Facets of sample meshes this many times finer than the scene meshes.
const MESH_DETAIL: usize = 4;

impl SampleDraw {
    /// Runs the press protocol on this draw (the frames' fields, not yet rendered).
    pub fn plan_press(
        &self,
        solver: &mut ContactSolver,
        catalog: &FruitCatalog,
        protocol: &PressProtocol,
    ) -> Result<PlannedPress, PressError> {
        let surface = self.surface(catalog);
        let optics = self.optics();
        let setup = PressSetup {
            surface: &surface,
            object: self.object(),
            gel: self.sensor.gel,
            fidelity: self.fidelity,
            optics: &optics,
            phase_mm: self.phase_mm,
            cell_mm: None,
            seed: self.noise_seed,
        };
        plan_press(solver, &setup, protocol)
    }

    pub fn object(&self) -> Elastic {
        Elastic {
            modulus_mpa: Some(self.modulus_mpa),
            poisson: self.object_poisson,
        }
    }

    /// The object's surface over the pad, its top at `offset_mm`, turned by `yaw_deg`.
    pub fn surface(&self, catalog: &FruitCatalog) -> ObjectSurface {
        let centre_mm = DVec2::from_array(self.offset_mm);
        let yaw_rad = self.yaw_deg.to_radians();
        let placed = |m: &mesh::TriMesh| {
            let top = mesh_top(m, 1.0);
            // The highest point of an irregular body need not sit over its bounding box's
            // middle: centre the pad on it, as the robot centres on the top it sees.
            let apex = top
                .vertices
                .iter()
                .min_by(|a, b| a.z.total_cmp(&b.z))
                .map_or(DVec2::ZERO, |v| v.truncate());
            let placed = top
                .transformed(DQuat::from_rotation_z(yaw_rad), centre_mm.extend(0.0))
                .transformed(
                    DQuat::IDENTITY,
                    -(DQuat::from_rotation_z(yaw_rad) * apex.extend(0.0)),
                );
            ObjectSurface::Mesh(near_the_pad(&placed, self.sensor.base.spec.pad_size_mm()))
        };
        match &self.shape {
            ShapeDraw::Sphere { radius_mm } => ObjectSurface::Sphere {
                radius_mm: *radius_mm,
                centre_mm,
            },
            ShapeDraw::Ellipsoid { semi_axes_mm } => ObjectSurface::Ellipsoid {
                semi_axes_mm: DVec3::from_array(*semi_axes_mm),
                centre_mm,
                yaw_rad,
            },
            ShapeDraw::Box { footprint_mm } => ObjectSurface::Box {
                size_mm: DVec2::from_array(*footprint_mm),
                centre_mm,
                yaw_rad,
            },
            ShapeDraw::Fruit { fruit, size_mm } => {
                let shape = catalog
                    .get(fruit)
                    .map(|f| f.shape)
                    .unwrap_or(tactex_core::catalog::FruitShape::Ellipsoid);
                placed(&mesh::fruit_detailed(
                    shape,
                    DVec3::from_array(*size_mm),
                    MESH_DETAIL,
                ))
            }
            ShapeDraw::Blob { size_mm, lobes } => {
                let lobes: Vec<Lobe> = lobes
                    .iter()
                    .map(|l| Lobe {
                        l: l[0] as u32,
                        m: l[1] as u32,
                        amplitude: l[2],
                        phase_theta: l[3],
                        phase_phi: l[4],
                    })
                    .collect();
                placed(&mesh::blob(
                    DVec3::from_array(*size_mm),
                    &lobes,
                    MESH_DETAIL,
                ))
            }
        }
    }

    /// The sensor as drawn: the profile's geometry with the randomised gel, lights and
    /// markers.
    pub fn spec(&self) -> TactileSpec {
        let d = &self.sensor;
        let mut spec = d.base.spec.clone();
        spec.gel = d.gel;
        spec.photometric = d.lighting;
        spec.markers.cols = d.marker_grid[0];
        spec.markers.rows = d.marker_grid[1];
        spec.markers.pitch_mm = d.marker_pitch_mm;
        spec.markers.radius_mm = d.marker_radius_mm;
        spec
    }

    /// The drawn sensor's optics: the profile's background (scaled per channel) and shading
    /// (its calibrated table, or the drawn lights), the drawn markers, noise and vignetting.
    pub fn optics(&self) -> SensorOptics {
        let d = &self.sensor;
        let drawn = SensorProfile {
            spec: self.spec(),
            noise_sigma_grey: d.noise_sigma,
            vignette: d.vignette,
            ..(*d.base).clone()
        };
        let mut optics = SensorOptics::for_profile(&drawn);
        for p in &mut optics.background {
            *p = std::array::from_fn(|c| p[c] * d.background_gain[c] as f32);
        }
        optics
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_draw_depends_only_on_seed_index_and_attempt() {
        let space = SampleSpace::default();
        let catalog = FruitCatalog::builtin();
        let a = space.draw(&catalog, 3, 17, 0);
        let b = space.draw(&catalog, 3, 17, 0);
        assert_eq!(a, b);
        assert_ne!(a, space.draw(&catalog, 3, 18, 0));
        assert_ne!(a, space.draw(&catalog, 3, 17, 1));
        assert_ne!(a, space.draw(&catalog, 4, 17, 0));
    }

    #[test]
    fn draws_cover_every_family_and_the_hardness_range_within_the_jitter() {
        let space = SampleSpace::default();
        let catalog = FruitCatalog::builtin();
        let draws: Vec<SampleDraw> = (0..400).map(|i| space.draw(&catalog, 1, i, 0)).collect();
        for family in ShapeFamily::ALL {
            assert!(draws.iter().any(|d| d.family == family), "{family}");
        }
        let soft = draws
            .iter()
            .map(|d| d.shore_00)
            .fold(f64::INFINITY, f64::min);
        let hard = draws.iter().map(|d| d.shore_a).fold(0.0, f64::max);
        assert!(
            soft < 20.0 && hard > 80.0,
            "Shore 00 {soft}, Shore A {hard}"
        );
        for d in &draws {
            assert!(d.offset_mm.iter().all(|o| o.abs() <= 5.0));
            assert!((0.0..=45.0).contains(&d.yaw_deg));
            assert!((0.0..0.25).contains(&d.phase_mm));
            d.surface(&catalog).validate().unwrap();
            d.optics().validate().unwrap();
        }
    }

    #[test]
    fn every_family_puts_its_top_at_the_drawn_offset() {
        let catalog = FruitCatalog::builtin();
        for family in ShapeFamily::ALL {
            let space = SampleSpace {
                families: vec![family],
                ..SampleSpace::default()
            };
            let d = space.draw(&catalog, 5, 0, 0);
            let surface = d.surface(&catalog);
            let pad = crate::contact::Rect::centred(DVec2::new(10.1, 7.6));
            let lowest = surface.lowest_over(&pad).expect("object over the pad");
            assert!(lowest.abs() < 1e-6, "{family}: lowest {lowest}");
            // The apex sits at the drawn offset.
            let offset = DVec2::from_array(d.offset_mm);
            let apex = surface.height_at(offset).expect("object under its offset");
            assert!(apex.abs() < 1e-3, "{family}: height {apex} at the offset");
        }
    }
}
