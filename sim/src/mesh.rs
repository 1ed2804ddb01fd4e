//! Triangle meshes: procedural fruit and primitive shapes, and OBJ / glTF files.

use glam::{DQuat, DVec3};
use std::f64::consts::PI;
use std::path::Path;
use tactex_core::catalog::FruitShape;
use tactex_core::printable::excerpt;
use tactex_core::text_file;

#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file system would not give the file (missing, unreadable): its error kept, so
    /// that a missing mesh can be told from a bad one.
    #[error("{path}: cannot read mesh: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: cannot read mesh: {message}")]
    Read { path: String, message: String },
    #[error("{path}: mesh has no triangles")]
    Empty { path: String },
    #[error("{path}: mesh is degenerate ({message})")]
    Degenerate { path: String, message: String },
    #[error("{path}: unsupported mesh format (use .obj, .gltf or .glb)")]
    Format { path: String },
}

impl TriMesh {
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.vertices.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        )
    }

    /// Whether `p` lies inside the mesh: its winding number, the solid angle its triangles
    /// subtend over 4 pi, is at least a half (Jacobson et al., SIGGRAPH 2013). Unlike a ray's
    /// parity it holds for meshes from scans and exporters: an open surface reads near 1
    /// inside, a face stored twice counts twice, and either orientation reads the same.
    pub fn contains(&self, p: DVec3) -> bool {
        self.winding_number(p).abs() >= 0.5
    }

    /// Sum of the signed solid angles of the triangles seen from `p`, over 4 pi (the formula of
    /// Van Oosterom and Strackee, 1983).
    fn winding_number(&self, p: DVec3) -> f64 {
        let total: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize] - p);
                let (la, lb, lc) = (a.length(), b.length(), c.length());
                let det = a.dot(b.cross(c));
                let div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
                2.0 * det.atan2(div)
            })
            .sum();
        total / (4.0 * std::f64::consts::PI)
    }

    /// Its largest extent in metres at `scale` (its units to metres) when that is not a size
    /// an object on a table has (`scene::OBJECT_SIZE_M`, as a scene's shapes); None when it is.
    pub fn size_off_table_m(&self, scale: f64) -> Option<f64> {
        let (lo, hi) = self.bounds();
        let size_m = (hi - lo).max_element() * scale;
        let [least, most] = tactex_core::scene::OBJECT_SIZE_M;
        (!(size_m.is_finite() && (least..=most).contains(&size_m))).then_some(size_m)
    }

    /// Scales each axis so the bounding box is `size` and centres it at the origin.
    fn fit_box(mut self, size: DVec3) -> Self {
        let (lo, hi) = self.bounds();
        let scale = size / (hi - lo).max(DVec3::splat(1e-12));
        let centre = (lo + hi) / 2.0;
        for v in &mut self.vertices {
            *v = (*v - centre) * scale;
        }
        self
    }

    /// The centre of the mesh's outline seen from above (x, y of the centroid of its
    /// projected upward-facing area; z its highest point): where a top-down camera's mask of
    /// it is centred. A curved banana's box centre lies off the fruit; this does not.
    pub fn top_view_centre(&self) -> DVec3 {
        let (mut sum, mut area) = (DVec3::ZERO, 0.0);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.vertices[i as usize]);
            // Twice the projected area, signed: positive where the face looks up.
            let up = (b - a).cross(c - a).z;
            if up > 0.0 {
                sum += (a + b + c) / 3.0 * up;
                area += up;
            }
        }
        let top = self.bounds().1.z;
        if area > 0.0 {
            let c = sum / area;
            DVec3::new(c.x, c.y, top)
        } else {
            let (lo, hi) = self.bounds();
            DVec3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, top)
        }
    }

    pub fn transformed(&self, rotation: DQuat, translation: DVec3) -> TriMesh {
        TriMesh {
            vertices: self
                .vertices
                .iter()
                .map(|v| rotation * *v + translation)
                .collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Area-weighted vertex normals (outward for consistently wound meshes).
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        let mut n = vec![DVec3::ZERO; self.vertices.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.vertices[i as usize]);
            let face = (b - a).cross(c - a);
            for &i in t {
                n[i as usize] += face;
            }
        }
        n.into_iter()
            .map(|v| v.try_normalize().unwrap_or(DVec3::Z))
            .collect()
    }

    /// Rejects meshes that cannot be simulated: no triangles, bad indices, non-finite or flat.
    pub fn validate(&self, path: &str) -> Result<(), MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::Empty { path: path.into() });
        }
        let bad = |message: &str| MeshError::Degenerate {
            path: path.into(),
            message: message.into(),
        };
        if self.triangles.len() < 4 || self.vertices.len() < 4 {
            return Err(bad(&format!(
                "{} triangles on {} vertices; a solid needs a closed surface of at least 4 triangles",
                self.triangles.len(),
                self.vertices.len()
            )));
        }
        if self.triangles.len() > MAX_TRIANGLES {
            return Err(bad(&format!(
                "{} triangles, over the {MAX_TRIANGLES} a mesh may have",
                self.triangles.len()
            )));
        }
        if self.vertices.iter().any(|v| !v.is_finite()) {
            return Err(bad("non-finite vertex"));
        }
        if self
            .triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= self.vertices.len())
        {
            return Err(bad("triangle index out of range"));
        }
        let (lo, hi) = self.bounds();
        let ext = hi - lo;
        if ext.min_element() <= 1e-6 * ext.max_element().max(1e-12) {
            return Err(bad(&format!(
                "flat or zero-size: its bounding box spans {:?} (mesh units), a side under a millionth of the longest",
                ext.to_array().map(|v| v as f32)
            )));
        }
        let area: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                (b - a).cross(c - a).length() / 2.0
            })
            .sum();
        if area <= 0.0 {
            return Err(bad("zero surface area"));
        }
        let open = self.open_edges();
        if open > 0 {
            return Err(bad(&format!(
                "the surface is open: {open} edges border one triangle only; a solid's mesh is closed (fill its holes)"
            )));
        }
        Ok(())
    }

    /// Edges that border one triangle only, vertices taken by position (exporters split a
    /// vertex where its normals or texture coordinates change). A gap there lets the gel
    /// reach inside: a cube missing its top was pressed on its floor, at no force.
    fn open_edges(&self) -> usize {
        let key = |i: u32| self.vertices[i as usize].to_array().map(f64::to_bits);
        let mut edges: std::collections::HashMap<_, usize> = std::collections::HashMap::new();
        for t in &self.triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let (a, b) = (key(a), key(b));
                if a == b {
                    continue;
                }
                *edges
                    .entry(if a < b { (a, b) } else { (b, a) })
                    .or_default() += 1;
            }
        }
        edges.values().filter(|&&n| n == 1).count()
    }
}

/// A closed latitude-longitude surface around the x axis: `profile(u)` gives the point for
/// u = (along in [0, 1], around in [0, 1)).
fn lat_long(along: usize, around: usize, point: impl Fn(f64, f64) -> DVec3) -> TriMesh {
    let mut m = TriMesh::default();
    m.vertices.push(point(0.0, 0.0));
    for i in 1..along {
        for j in 0..around {
            m.vertices
                .push(point(i as f64 / along as f64, j as f64 / around as f64));
        }
    }
    m.vertices.push(point(1.0, 0.0));
    let ring = |i: usize, j: usize| (1 + (i - 1) * around + j % around) as u32;
    let last = (m.vertices.len() - 1) as u32;
    for j in 0..around {
        m.triangles.push([0, ring(1, j + 1), ring(1, j)]);
        m.triangles
            .push([last, ring(along - 1, j), ring(along - 1, j + 1)]);
    }
    for i in 1..along - 1 {
        for j in 0..around {
            m.triangles
                .push([ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)]);
            m.triangles
                .push([ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)]);
        }
    }
    m
}

const ALONG: usize = 48;
const AROUND: usize = 96;

/// An ellipsoid with semi-axes `radii`.
pub fn ellipsoid(radii: DVec3) -> TriMesh {
    ellipsoid_at(radii, 1)
}

fn ellipsoid_at(radii: DVec3, detail: usize) -> TriMesh {
    lat_long(ALONG * detail, AROUND * detail, |t, s| {
        let (theta, phi) = (PI * t, 2.0 * PI * s);
        DVec3::new(
            -theta.cos(),
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
        ) * radii
    })
}

/// An egg: cross-sections swell towards the -x end, fitted to the bounding box `size`.
pub fn egg(size: DVec3) -> TriMesh {
    egg_at(size, 1)
}

fn egg_at(size: DVec3, detail: usize) -> TriMesh {
    lat_long(ALONG * detail, AROUND * detail, |t, s| {
        let (theta, phi) = (PI * t, 2.0 * PI * s);
        let x = -theta.cos();
        let swell = 1.0 - 0.22 * x;
        DVec3::new(
            x,
            swell * theta.sin() * phi.cos(),
            swell * theta.sin() * phi.sin(),
        )
    })
    .fit_box(size)
}

/// A banana: a tube tapering to both tips, bent along a circular arc in the x-y plane,
/// fitted to the bounding box `size` (length, width including the bend, thickness).
pub fn banana(size: DVec3) -> TriMesh {
    banana_at(size, 1)
}

fn banana_at(size: DVec3, detail: usize) -> TriMesh {
    let half_angle: f64 = 0.5;
    let bend = ((size.y - size.z).max(0.0) / (1.0 - half_angle.cos())).max(1e-6);
    let tube = size.z / 2.0;
    lat_long(ALONG * detail, AROUND * detail, |t, s| {
        let a = (2.0 * t - 1.0) * half_angle;
        let taper = (1.0 - (2.0 * t - 1.0).powi(4))
            .max(0.0)
            .powf(0.35)
            .max(0.05);
        let centre = DVec3::new(bend * a.sin(), bend * (1.0 - a.cos()), 0.0);
        let tangent = DVec3::new(a.cos(), a.sin(), 0.0);
        let normal = DVec3::new(-a.sin(), a.cos(), 0.0);
        let phi = 2.0 * PI * s;
        let r = tube * taper;
        // Tips close the tube along its tangent.
        let tip = if t == 0.0 {
            -tube * 0.3
        } else if t == 1.0 {
            tube * 0.3
        } else {
            0.0
        };
        centre + tangent * tip + (normal * phi.cos() + DVec3::Z * phi.sin()) * r
    })
    .fit_box(size)
}

pub fn cuboid(size: DVec3) -> TriMesh {
    let h = size / 2.0;
    let vertices = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriMesh {
        vertices,
        triangles,
    }
}

pub fn fruit(shape: FruitShape, size: DVec3) -> TriMesh {
    fruit_detailed(shape, size, 1)
}

/// A fruit tessellated `detail` times finer along and around than the scene meshes: contact
/// solvers that read the mesh's facets need them well below the contact's size.
pub fn fruit_detailed(shape: FruitShape, size: DVec3, detail: usize) -> TriMesh {
    let detail = detail.max(1);
    match shape {
        FruitShape::Ellipsoid => ellipsoid_at(size / 2.0, detail),
        FruitShape::Egg => egg_at(size, detail),
        FruitShape::Banana => banana_at(size, detail),
    }
}

/// One smooth random lobe of a blob: r *= 1 + amplitude * cos(l theta + phase_t) cos(m phi +
/// phase_p).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe {
    pub l: u32,
    pub m: u32,
    pub amplitude: f64,
    pub phase_theta: f64,
    pub phase_phi: f64,
}

/// A smooth star-shaped random body: an ellipsoid whose radius is modulated by low-order
/// lobes (the total modulation is kept under 1/2 so that it stays star-shaped), fitted to
/// `size`. Unseen shapes for hardness models trained on primitives and fruit.
pub fn blob(size: DVec3, lobes: &[Lobe], detail: usize) -> TriMesh {
    let total: f64 = lobes.iter().map(|l| l.amplitude.abs()).sum();
    let norm = if total > 0.45 { 0.45 / total } else { 1.0 };
    let detail = detail.max(1);
    lat_long(ALONG * detail, AROUND * detail, |t, s| {
        let (theta, phi) = (PI * t, 2.0 * PI * s);
        let r = 1.0
            + norm
                * lobes
                    .iter()
                    .map(|l| {
                        l.amplitude
                            * (l.l as f64 * theta + l.phase_theta).cos()
                            * (l.m as f64 * phi + l.phase_phi).cos()
                    })
                    .sum::<f64>();
        DVec3::new(
            -theta.cos(),
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
        ) * r
    })
    .fit_box(size)
}

/// Loads an OBJ or glTF/GLB mesh (all its triangles, node transforms applied), in metres.
/// The largest mesh file read (bytes) and the most triangles simulated: a fruit scanned at
/// 0.1 mm is well inside both.
pub const MAX_MESH_BYTES: u64 = 256 << 20;
pub const MAX_TRIANGLES: usize = 2_000_000;

/// The path a glTF buffer URI names: relative to the glTF's folder (percent-encoded, as the
/// glTF spec writes it) or `file:`; other schemes are refused.
fn gltf_buffer_path(dir: &Path, uri: &str) -> Result<std::path::PathBuf, String> {
    if uri.contains(':') {
        let rest = uri
            .strip_prefix("file://")
            .or_else(|| uri.strip_prefix("file:"))
            .ok_or_else(|| format!("buffer URI '{uri}' has a scheme other than file: or data:"))?;
        return Ok(std::path::PathBuf::from(rest));
    }
    let decoded = percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .map_err(|_| format!("buffer URI '{uri}' is not UTF-8 once percent-decoded"))?;
    Ok(dir.join(&*decoded))
}

/// The data of every buffer of a glTF, its external files read with the same bound as the
/// mesh file itself (the importer's own reader would wait on a FIFO and read a device whole).
fn gltf_buffers(
    doc: &gltf::Document,
    dir: &Path,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<gltf::buffer::Data>, String> {
    let mut buffers = Vec::new();
    let mut total = 0u64;
    for buffer in doc.buffers() {
        let mut data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                format!(
                    "buffer {} is the GLB chunk, which is missing",
                    buffer.index()
                )
            })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                gltf::buffer::Data::from_source(buffer.source(), None)
                    .map_err(|e| format!("buffer {}: {e}", buffer.index()))?
                    .0
            }
            gltf::buffer::Source::Uri(uri) => {
                let file = gltf_buffer_path(dir, uri)?;
                text_file::read_bytes(&file, MAX_MESH_BYTES).map_err(|e| match e.kind() {
                    std::io::ErrorKind::NotFound => {
                        format!(
                            "buffer {} file '{}' not found",
                            buffer.index(),
                            file.display()
                        )
                    }
                    _ => format!("buffer {} file '{}': {e}", buffer.index(), file.display()),
                })?
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} has {} bytes, the glTF says {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        // Accessors read whole 4-byte words.
        data.resize(data.len().next_multiple_of(4), 0);
        // Many buffers naming one large file would each read it whole.
        total += data.len() as u64;
        if total > MAX_MESH_BYTES {
            return Err(format!(
                "its buffers hold over the {} MB a mesh may have",
                MAX_MESH_BYTES >> 20
            ));
        }
        buffers.push(gltf::buffer::Data(data));
    }
    Ok(buffers)
}

pub fn load(path: &Path) -> Result<TriMesh, MeshError> {
    let shown = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let read_err = |message: String| MeshError::Read {
        path: shown.clone(),
        message,
    };
    // The format is known before the file is read.
    let is_obj = match ext.as_str() {
        "obj" => true,
        "gltf" | "glb" => false,
        _ => return Err(MeshError::Format { path: shown }),
    };
    // One bounded read: a FIFO or a device is refused, an oversize file is not read whole.
    let bytes =
        text_file::read_bytes(path, MAX_MESH_BYTES).map_err(|source| match source.kind() {
            std::io::ErrorKind::InvalidData => read_err(format!(
                "over the {} MB a mesh file may have",
                MAX_MESH_BYTES >> 20
            )),
            _ => MeshError::Io {
                path: shown.clone(),
                source,
            },
        })?;
    let mesh = match is_obj {
        true => {
            let opts = tobj::LoadOptions {
                triangulate: true,
                single_index: true,
                ..Default::default()
            };
            if let Some(problem) = std::str::from_utf8(&bytes).ok().and_then(obj_line_problem) {
                return Err(read_err(problem));
            }
            // Materials are not simulated: an `mtllib` is never opened.
            let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &opts, |_| {
                Err(tobj::LoadError::OpenFileFailed)
            })
            .map_err(|e| read_err(obj_failure(&bytes, e)))?;
            let mut m = TriMesh::default();
            for model in models {
                let base = m.vertices.len() as u32;
                m.vertices.extend(
                    model
                        .mesh
                        .positions
                        .chunks_exact(3)
                        .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
                );
                m.triangles.extend(
                    model
                        .mesh
                        .indices
                        .chunks_exact(3)
                        .map(|t| [base + t[0], base + t[1], base + t[2]]),
                );
            }
            m
        }
        false => {
            let gltf::Gltf {
                document: doc,
                blob,
            } = gltf::Gltf::from_slice_without_validation(&bytes)
                .map_err(|e| read_err(e.to_string()))?;
            // gltf-json's validation indexes a POSITION accessor before checking it exists
            // (a panic): that one is checked here first, then the whole document validated.
            positions_exist(doc.as_json()).map_err(read_err)?;
            let doc =
                gltf::Document::from_json(doc.into_json()).map_err(|e| read_err(e.to_string()))?;
            let dir = path.parent().unwrap_or(Path::new("."));
            let buffers = gltf_buffers(&doc, dir, blob).map_err(read_err)?;
            let mut m = TriMesh::default();
            let scene = doc
                .default_scene()
                .or_else(|| doc.scenes().next())
                .ok_or_else(|| MeshError::Empty {
                    path: shown.clone(),
                })?;
            gltf_nodes(&doc, scene.nodes(), &buffers, &mut m).map_err(read_err)?;
            m
        }
    };
    mesh.validate(&shown)?;
    Ok(mesh)
}

/// Why an OBJ could not be read, in words a user can act on: tobj says only "read error"
/// for a file that is not text.
fn obj_failure(bytes: &[u8], e: tobj::LoadError) -> String {
    match (e, std::str::from_utf8(bytes)) {
        (tobj::LoadError::ReadError, Err(bad)) => {
            let line = 1 + bytes[..bad.valid_up_to()]
                .iter()
                .filter(|b| **b == b'\n')
                .count();
            format!("line {line} is not UTF-8 text; a Wavefront OBJ is a text file")
        }
        (e, _) => format!("{e}, in a Wavefront OBJ line"),
    }
}

/// The first line of an OBJ that its parser would refuse without saying where, or would
/// drop (a face of fewer than three vertices): a vertex whose coordinates are not numbers,
/// a face whose index is not one or names no vertex read so far.
fn obj_line_problem(text: &str) -> Option<String> {
    let (mut positions, mut texcoords, mut normals) = (0i64, 0i64, 0i64);
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let (kind, rest) = (words.next(), words);
        let numbers = |wanted: usize, what: &str, rest: std::str::SplitWhitespace| {
            let read: Vec<&str> = rest.take(wanted).collect();
            let needs = if wanted == 1 {
                "a number".to_string()
            } else {
                format!("{wanted} numbers")
            };
            (read.len() < wanted || read.iter().any(|w| w.parse::<f32>().is_err())).then(|| {
                format!(
                    "line {}: {what} needs {needs}, has '{}'",
                    n + 1,
                    excerpt(line, 60)
                )
            })
        };
        let problem = match kind {
            Some("v") => {
                positions += 1;
                numbers(3, "a vertex (v)", rest)
            }
            Some("vt") => {
                texcoords += 1;
                numbers(1, "a texture coordinate (vt)", rest)
            }
            Some("vn") => {
                normals += 1;
                numbers(3, "a normal (vn)", rest)
            }
            Some("f") => {
                let corners: Vec<&str> = rest.collect();
                if corners.len() < 3 {
                    Some(format!(
                        "line {}: a face (f) of {} vertices; a face needs 3 or more",
                        n + 1,
                        corners.len()
                    ))
                } else {
                    corners.iter().find_map(|corner| {
                        let bad = corner.split('/').zip([positions, texcoords, normals]).any(
                            |(index, count)| {
                                !index.is_empty()
                                    && !index.parse::<i64>().is_ok_and(|i| {
                                        (1..=count).contains(&i) || (-count..=-1).contains(&i)
                                    })
                            },
                        );
                        (bad || corner.starts_with('/')).then(|| {
                            format!(
                                "line {}: face corner '{}' names no vertex read before it \
                                 (1-based, or negative from the last)",
                                n + 1,
                                excerpt(corner, 60)
                            )
                        })
                    })
                }
            }
            _ => None,
        };
        if problem.is_some() {
            return problem;
        }
    }
    None
}

/// Every primitive's POSITION names an accessor the file has.
fn positions_exist(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::Checked;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(gltf::json::mesh::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not \
                     exist (the file has {})",
                    index.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// Where an accessor's dense elements lie in its buffer, checked against the bytes there:
/// one reaching past its view or buffer was read as no triangles.
fn accessor_in_buffer(a: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> Result<(), String> {
    let Some(view) = a.view() else {
        return Ok(());
    };
    let stride = view.stride().unwrap_or(a.size());
    // Checked sums: offsets near 2^64 wrapped past the comparison.
    let needed = match a.count() {
        0 => Some(0),
        n => stride
            .checked_mul(n - 1)
            .and_then(|v| v.checked_add(a.offset()))
            .and_then(|v| v.checked_add(a.size())),
    };
    let held = buffers.get(view.buffer().index()).map_or(0, |d| d.0.len());
    let view_end = view.offset().checked_add(view.length());
    if needed.is_none_or(|n| n > view.length()) || view_end.is_none_or(|e| e > held) {
        let needed = needed.map_or("more than 2^64".into(), |n| n.to_string());
        return Err(format!(
            "accessor {} needs {needed} bytes of buffer view {} ({} bytes at {}), whose buffer holds {held}",
            a.index(),
            view.index(),
            view.length(),
            view.offset()
        ));
    }
    Ok(())
}

/// An accessor's sparse substitutions, checked where gltf's reader does not: a count past
/// the accessor's read as no triangles, an index past its elements or out of order was
/// dropped without a word, a strided view dropped the primitive, and the indices' and
/// values' views must hold what they are said to (glTF 2.0, 3.6.2.3).
fn sparse_in_bounds(a: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> Result<(), String> {
    let Some(sparse) = a.sparse() else {
        return Ok(());
    };
    let n = sparse.count();
    if n == 0 {
        return Err(format!(
            "accessor {}: sparse.count is 0; a sparse part substitutes at least one element",
            a.index()
        ));
    }
    if n > a.count() {
        return Err(format!(
            "accessor {}: sparse.count {n} is more than its {} elements",
            a.index(),
            a.count()
        ));
    }
    let indices = sparse.indices();
    let size = indices.index_type().size();
    // The bytes of a sparse part's view from `offset`, if `needed` of them are there.
    let bytes = |view: gltf::buffer::View, offset: usize, needed: Option<usize>, part: &str| {
        if let Some(stride) = view.stride() {
            return Err(format!(
                "accessor {}: sparse.{part}'s buffer view {} has byteStride {stride}; a sparse part's view is tightly packed and has none",
                a.index(),
                view.index()
            ));
        }
        // Every element starts at a multiple of its component's size.
        let component = if part == "indices" {
            size
        } else {
            a.data_type().size()
        };
        let start = view.offset().checked_add(offset);
        if let Some(at) = start.filter(|at| !at.is_multiple_of(component)) {
            return Err(format!(
                "accessor {}: sparse.{part} starts at byte {at} of its buffer (byteOffset {offset} of buffer view {}), not a multiple of its {component}-byte component",
                a.index(),
                view.index()
            ));
        }
        let held = buffers.get(view.buffer().index()).map(|d| &d.0[..]);
        let end = start.zip(needed).and_then(|(s, n)| s.checked_add(n));
        match (held, start, end) {
            (Some(held), Some(start), Some(end))
                if offset <= view.length()
                    && needed.is_some_and(|n| n <= view.length() - offset)
                    && end <= held.len() =>
            {
                Ok(&held[start..end])
            }
            _ => Err(format!(
                "accessor {}: sparse.{part} needs {} bytes from byteOffset {offset} of buffer view {} ({} bytes at {})",
                a.index(),
                needed.map_or("more than 2^64".into(), |n| n.to_string()),
                view.index(),
                view.length(),
                view.offset()
            )),
        }
    };
    let raw = bytes(
        indices.view(),
        indices.offset(),
        n.checked_mul(size),
        "indices",
    )?;
    let values = sparse.values();
    bytes(
        values.view(),
        values.offset(),
        n.checked_mul(a.size()),
        "values",
    )?;
    let mut last = None;
    for (k, chunk) in raw.chunks_exact(size).enumerate() {
        let index = chunk
            .iter()
            .rev()
            .fold(0usize, |v, b| (v << 8) | *b as usize);
        if index >= a.count() {
            return Err(format!(
                "accessor {}: sparse.indices[{k}] is {index}, past its {} elements",
                a.index(),
                a.count()
            ));
        }
        if let Some(before) = last.filter(|b| *b >= index) {
            return Err(format!(
                "accessor {}: sparse.indices[{k}] is {index}, after {before}; they must increase",
                a.index()
            ));
        }
        last = Some(index);
    }
    Ok(())
}

/// The triangles of every node under `roots`, walked without recursion: a node reached
/// twice (a cycle, or a child shared by two parents, which glTF forbids) is refused, as is
/// an accessor whose stride is shorter than its element or whose count alone passes the
/// triangle limit, before anything is read from it.
fn gltf_nodes<'a>(
    doc: &gltf::Document,
    roots: impl Iterator<Item = gltf::Node<'a>>,
    buffers: &[gltf::buffer::Data],
    out: &mut TriMesh,
) -> Result<(), String> {
    let mut reached = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, glam::DMat4)> =
        roots.map(|n| (n, glam::DMat4::IDENTITY)).collect();
    let readable = |a: &gltf::Accessor| -> Result<(), String> {
        if a.count() > 3 * MAX_TRIANGLES {
            return Err(format!(
                "accessor {} has {} elements, more than {MAX_TRIANGLES} triangles need",
                a.index(),
                a.count()
            ));
        }
        if let Some(view) = a.view()
            && let Some(stride) = view.stride()
            && stride < a.size()
        {
            return Err(format!(
                "accessor {}: byteStride {stride} is less than its {}-byte element",
                a.index(),
                a.size()
            ));
        }
        Ok(())
    };
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut reached[node.index()], true) {
            return Err(format!(
                "node {} is reached twice (a cycle, or a child of two parents)",
                node.index()
            ));
        }
        // glTF's rotation is a unit quaternion; another length would scale and shear the
        // mesh as a matrix built from it.
        if let gltf::scene::Transform::Decomposed { rotation, .. } = node.transform() {
            let length = rotation.iter().map(|v| v * v).sum::<f32>().sqrt();
            if (length - 1.0).abs() > 1e-3 {
                return Err(format!(
                    "nodes[{}].rotation {rotation:?} is not a unit quaternion (length {length})",
                    node.index()
                ));
            }
        }
        let local = glam::Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    continue;
                }
                use gltf::accessor::{DataType, Dimensions};
                if let Some(p) = prim.get(&gltf::Semantic::Positions)
                    && (p.data_type() != DataType::F32 || p.dimensions() != Dimensions::Vec3)
                {
                    // The reader takes any POSITION as three floats: u8 ones read as garbage.
                    return Err(format!(
                        "accessor {}: POSITION is {:?} {:?}, expected VEC3 of FLOAT",
                        p.index(),
                        p.dimensions(),
                        p.data_type()
                    ));
                }
                if let Some(i) = prim.indices()
                    && (!matches!(i.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
                        || i.dimensions() != Dimensions::Scalar)
                {
                    // The reader reaches unreachable code on any other index type.
                    return Err(format!(
                        "accessor {}: indices are {:?} {:?}, expected SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
                        i.index(),
                        i.dimensions(),
                        i.data_type()
                    ));
                }
                for accessor in prim
                    .get(&gltf::Semantic::Positions)
                    .into_iter()
                    .chain(prim.indices())
                {
                    readable(&accessor)?;
                    accessor_in_buffer(&accessor, buffers)?;
                    sparse_in_bounds(&accessor, buffers)?;
                }
                let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
                let Some(positions) = reader.read_positions() else {
                    return Err(format!(
                        "mesh {}: primitive {}: its POSITION could not be read",
                        mesh.index(),
                        prim.index()
                    ));
                };
                // Every node using a mesh adds its vertices again: bounded in all, not per
                // accessor (300 nodes on one million-vertex accessor asked for 7 GB).
                if out.vertices.len() + positions.len() > 3 * MAX_TRIANGLES {
                    return Err(format!(
                        "more than {} vertices over the scene's nodes",
                        3 * MAX_TRIANGLES
                    ));
                }
                let base = out.vertices.len() as u32;
                out.vertices.extend(positions.map(|p| {
                    world.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                }));
                let count = out.vertices.len() as u32 - base;
                match reader.read_indices() {
                    Some(idx) => {
                        let idx: Vec<u32> = idx.into_u32().collect();
                        if let Some(bad) = idx.iter().find(|i| **i >= count) {
                            return Err(format!(
                                "mesh {} index {bad} is past its {count} vertices",
                                mesh.index()
                            ));
                        }
                        out.triangles.extend(
                            idx.chunks_exact(3)
                                .map(|t| [base + t[0], base + t[1], base + t[2]]),
                        );
                    }
                    None => out.triangles.extend(
                        (0..count / 3).map(|i| [base + 3 * i, base + 3 * i + 1, base + 3 * i + 2]),
                    ),
                }
                if out.triangles.len() > MAX_TRIANGLES {
                    return Err(format!("more than {MAX_TRIANGLES} triangles"));
                }
            }
        }
        stack.extend(node.children().map(|child| (child, world)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {

    #[test]
    fn a_point_is_inside_a_mesh_by_its_winding_number() {
        let ball = ellipsoid(DVec3::new(0.03, 0.02, 0.04));
        assert!(ball.contains(DVec3::ZERO));
        assert!(ball.contains(DVec3::new(0.025, 0.0, 0.0)));
        assert!(!ball.contains(DVec3::new(0.035, 0.0, 0.0)));
        assert!(!ball.contains(DVec3::new(0.0, 0.0, 0.05)));
        assert!(!ball.contains(DVec3::new(0.0, 0.0, -0.05)));
        let cube = cuboid(DVec3::splat(0.02));
        assert!(cube.contains(DVec3::new(0.009, -0.009, 0.009)));
        assert!(!cube.contains(DVec3::new(0.011, 0.0, 0.0)));
        // Exporters' meshes: faces stored twice, a face missing, the faces turned inside out.
        let inside = DVec3::new(0.005, -0.004, 0.003);
        let outside = DVec3::new(0.0, 0.0, 0.015);
        let mut twice = cube.clone();
        twice.triangles.extend(cube.triangles.clone());
        let mut open = cube.clone();
        open.triangles.truncate(open.triangles.len() - 2);
        let mut turned = cube.clone();
        for t in &mut turned.triangles {
            t.swap(1, 2);
        }
        for (name, mesh) in [("twice", &twice), ("open", &open), ("turned", &turned)] {
            assert!(mesh.contains(inside), "{name}");
            assert!(!mesh.contains(outside), "{name}");
        }
    }

    use super::*;

    #[test]
    fn procedural_fruit_fill_their_bounding_box() {
        let size = DVec3::new(0.19, 0.06, 0.036);
        for shape in [FruitShape::Ellipsoid, FruitShape::Egg, FruitShape::Banana] {
            let (lo, hi) = fruit(shape, size).bounds();
            assert!(((hi - lo) - size).abs().max_element() < 1e-9, "{shape:?}");
        }
    }

    #[test]
    fn ellipsoid_vertices_lie_on_the_surface_and_face_out() {
        let r = DVec3::new(0.05, 0.04, 0.03);
        let m = ellipsoid(r);
        for v in &m.vertices {
            assert!(((*v / r).length_squared() - 1.0).abs() < 1e-9);
        }
        let n = m.vertex_normals();
        assert!(
            m.vertices.iter().zip(&n).all(|(v, n)| v.dot(*n) > 0.0),
            "normals point outward"
        );
    }

    #[test]
    fn bad_mesh_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty.obj");
        std::fs::write(&empty, "# nothing\n").unwrap();
        assert!(load(&empty).unwrap_err().to_string().contains("empty.obj"));
        let flat = dir.path().join("flat.obj");
        std::fs::write(
            &flat,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
        )
        .unwrap();
        assert!(load(&flat).unwrap_err().to_string().contains("degenerate"));
        // One vertex 1e30 out: the box is named, so the far vertex is found, not hunted for.
        let far = dir.path().join("far.obj");
        std::fs::write(
            &far,
            "v 0 0 0\nv 1e30 0 0\nv 0 0.05 0\nv 0 0 0.05\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n",
        )
        .unwrap();
        let e = load(&far).unwrap_err().to_string();
        assert!(e.contains("bounding box spans [1e30, 0.05, 0.05]"), "{e}");
        let garbage = dir.path().join("bad.glb");
        std::fs::write(&garbage, "not a gltf").unwrap();
        assert!(
            load(&garbage)
                .unwrap_err()
                .to_string()
                .starts_with(&garbage.display().to_string())
        );
        assert!(load(&dir.path().join("missing.obj")).is_err());
        // A cube without its top: the gel reached its floor and read no force.
        let cube = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
            f 1 3 2\nf 2 3 4\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
        let open = dir.path().join("open.obj");
        std::fs::write(&open, cube).unwrap();
        let e = load(&open).unwrap_err().to_string();
        assert!(
            e.contains("open.obj") && e.contains("the surface is open: 4 edges"),
            "{e}"
        );
        let closed = dir.path().join("closed.obj");
        std::fs::write(&closed, format!("{cube}f 5 6 8\nf 5 8 7\n")).unwrap();
        assert!(load(&closed).is_ok());
    }

    /// A closed tetrahedron, 5 cm across, as a glTF naming its one buffer by `uri`.
    fn tetra_gltf(uri: &str) -> (String, Vec<u8>) {
        let v: [[f32; 3]; 4] = [
            [0.0; 3],
            [0.05, 0.0, 0.0],
            [0.0, 0.05, 0.0],
            [0.0, 0.0, 0.05],
        ];
        let idx: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
        let mut bin: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        bin.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":72,"uri":"{uri}"}}],
"bufferViews":[{{"buffer":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":24}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","max":[0.05,0.05,0.05],"min":[0,0,0]}},
{{"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}}]}}"#
        );
        (json, bin)
    }

    #[test]
    fn a_sparse_accessor_reaching_past_its_elements_or_its_views_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (json, bin) = tetra_gltf("tetra.bin");
        // One sparse substitution: its index (u16) at byte 72, its VEC3 value at 76.
        let sparse_bin = |index: u16| {
            let mut b = bin.clone();
            b.extend(index.to_le_bytes());
            b.extend([0u8; 2]);
            b.extend([0.01f32, 0.0, 0.0].iter().flat_map(|x| x.to_le_bytes()));
            b
        };
        let with_sparse = |sparse: &str| {
            json.replace(r#""byteLength":72,"#, r#""byteLength":88,"#)
                .replace(
                    r#"{"buffer":0,"byteOffset":48,"byteLength":24}]"#,
                    r#"{"buffer":0,"byteOffset":48,"byteLength":24},{"buffer":0,"byteOffset":72,"byteLength":2},{"buffer":0,"byteOffset":76,"byteLength":12}]"#,
                )
                .replace(r#""min":[0,0,0]}"#, &format!(r#""min":[0,0,0],"sparse":{sparse}}}"#))
        };
        let one = r#"{"count":1,"indices":{"bufferView":2,"componentType":5123},"values":{"bufferView":3}}"#;
        let load_with = |index: u16, sparse: &str| {
            std::fs::write(dir.path().join("tetra.bin"), sparse_bin(index)).unwrap();
            let path = dir.path().join("sparse.gltf");
            std::fs::write(&path, with_sparse(sparse)).unwrap();
            load(&path).map_err(|e| e.to_string())
        };
        // A substitution inside the accessor is read: vertex 1 moved to x = 1 cm.
        let moved = load_with(1, one).unwrap();
        assert!(
            moved.vertices.iter().any(|v| (v.x - 0.01).abs() < 1e-9),
            "{:?}",
            moved.vertices
        );
        let past = load_with(100, one).unwrap_err();
        assert!(
            past.contains("sparse.indices[0] is 100, past its 4 elements"),
            "{past}"
        );
        let many = load_with(1, &one.replace(r#""count":1"#, r#""count":1000"#)).unwrap_err();
        assert!(
            many.contains("sparse.count 1000 is more than its 4 elements"),
            "{many}"
        );
        let far = load_with(
            1,
            &one.replace(
                r#""values":{"bufferView":3}"#,
                r#""values":{"bufferView":3,"byteOffset":8}"#,
            ),
        )
        .unwrap_err();
        assert!(
            far.contains("sparse.values needs 12 bytes from byteOffset 8 of buffer view 3"),
            "{far}"
        );
        // Two substitutions must name increasing vertices.
        let two = one
            .replace(r#""count":1"#, r#""count":2"#)
            .replace(r#""componentType":5123"#, r#""componentType":5121"#);
        let mut b = bin.clone();
        b.extend([2u8, 1, 0, 0]);
        b.extend(
            [0.01f32, 0.0, 0.0, 0.0, 0.01, 0.0]
                .iter()
                .flat_map(|x| x.to_le_bytes()),
        );
        std::fs::write(dir.path().join("tetra.bin"), b).unwrap();
        let path = dir.path().join("sparse.gltf");
        let text = with_sparse(&two)
            .replace(r#""byteLength":88,"#, r#""byteLength":100,"#)
            .replace(
                r#"{"buffer":0,"byteOffset":76,"byteLength":12}"#,
                r#"{"buffer":0,"byteOffset":76,"byteLength":24}"#,
            );
        std::fs::write(&path, &text).unwrap();
        let unsorted = load(&path).map_err(|e| e.to_string()).unwrap_err();
        assert!(
            unsorted.contains("sparse.indices[1] is 1, after 2; they must increase"),
            "{unsorted}"
        );
        // A sparse part's view has no stride.
        std::fs::write(dir.path().join("tetra.bin"), sparse_bin(1)).unwrap();
        let strided = with_sparse(one).replace(
            r#"{"buffer":0,"byteOffset":76,"byteLength":12}"#,
            r#"{"buffer":0,"byteOffset":76,"byteLength":12,"byteStride":16}"#,
        );
        std::fs::write(&path, strided).unwrap();
        let strided = load(&path).map_err(|e| e.to_string()).unwrap_err();
        assert!(strided.contains("has byteStride 16"), "{strided}");
        let none = load_with(1, &one.replace(r#""count":1"#, r#""count":0"#)).unwrap_err();
        assert!(none.contains("sparse.count is 0"), "{none}");
        let askew = load_with(
            1,
            &one.replace(
                r#""values":{"bufferView":3}"#,
                r#""values":{"bufferView":3,"byteOffset":2}"#,
            ),
        )
        .unwrap_err();
        assert!(
            askew.contains("sparse.values starts at byte 78 of its buffer"),
            "{askew}"
        );
    }

    #[test]
    fn a_position_naming_no_accessor_or_a_long_rotation_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (json, bin) = tetra_gltf("tetra.bin");
        std::fs::write(dir.path().join("tetra.bin"), bin).unwrap();
        let path = dir.path().join("missing-accessor.gltf");
        std::fs::write(&path, json.replace(r#""POSITION":0"#, r#""POSITION":7"#)).unwrap();
        let e = load(&path).unwrap_err().to_string();
        let rotated = dir.path().join("long-rotation.gltf");
        let long = json.replace(r#"{"mesh":0}"#, r#"{"mesh":0,"rotation":[0,0,0,2]}"#);
        std::fs::write(&rotated, long).unwrap();
        let r = load(&rotated).unwrap_err().to_string();
        assert!(
            r.contains("nodes[0].rotation") && r.contains("not a unit quaternion"),
            "{r}"
        );
        assert!(
            e.contains("missing-accessor.gltf")
                && e.contains("meshes[0].primitives[0].attributes.POSITION")
                && e.contains("accessor 7"),
            "{e}"
        );
    }

    #[test]
    fn an_obj_line_that_cannot_be_read_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let refused = |text: &str| {
            let path = dir.path().join("bad.obj");
            std::fs::write(&path, text).unwrap();
            load(&path).unwrap_err().to_string()
        };
        let tet = "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\n";
        for (text, says) in [
            (
                format!("{tet}f 1 3 2\nf 1 2\n"),
                "line 6: a face (f) of 2 vertices",
            ),
            (format!("{tet}f 1 3\n"), "line 5: a face (f) of 2 vertices"),
            (format!("{tet}f 1 3 9\n"), "line 5: face corner '9'"),
            (format!("{tet}f 1 3 -5\n"), "line 5: face corner '-5'"),
            (format!("{tet}f 1 3 x\n"), "line 5: face corner 'x'"),
            (format!("{tet}f 1/7 3 2\n"), "line 5: face corner '1/7'"),
            (
                format!("v 0 0\n{tet}"),
                "line 1: a vertex (v) needs 3 numbers",
            ),
            (
                format!("{tet}vn 0 zero 1\n"),
                "line 5: a normal (vn) needs 3 numbers",
            ),
        ] {
            let e = refused(&text);
            assert!(e.contains("bad.obj") && e.contains(says), "{says}: {e}");
        }
        // Negative (relative) corners and texture/normal slots are read.
        let path = dir.path().join("good.obj");
        std::fs::write(
            &path,
            format!("{tet}vt 0 0\nvn 0 0 1\nf -4/1/1 -2//1 -3\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"),
        )
        .unwrap();
        assert_eq!(load(&path).unwrap().triangles.len(), 4);
    }

    #[test]
    fn a_mesh_or_the_files_it_names_being_a_device_is_refused_not_read() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path();
        // A mesh that is a device: refused before it is read (it would never end).
        let zero = p.join("zero.obj");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let e = load(&zero).unwrap_err().to_string();
        assert!(
            e.contains("zero.obj") && e.contains("not a regular file"),
            "{e}"
        );
        // An OBJ's material library is never opened: a device there does not block the mesh.
        let tet =
            "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
        let with_mtl = p.join("with-mtl.obj");
        std::fs::write(&with_mtl, format!("mtllib /dev/zero\n{tet}")).unwrap();
        assert_eq!(load(&with_mtl).unwrap().triangles.len(), 4);
        // A glTF's buffer: percent-encoded names are read, a device behind file: is refused.
        // The glTF written as `name`, and why it was refused.
        let refused = |name: &str, json: String| {
            std::fs::write(p.join(name), json).unwrap();
            load(&p.join(name)).unwrap_err().to_string()
        };
        let (json, bin) = tetra_gltf("tetra%20mesh.bin");
        std::fs::write(p.join("tetra mesh.bin"), &bin).unwrap();
        std::fs::write(p.join("t.gltf"), &json).unwrap();
        assert_eq!(load(&p.join("t.gltf")).unwrap().triangles.len(), 4);
        let e = refused("z.gltf", tetra_gltf("file:///dev/zero").0);
        assert!(
            e.contains("z.gltf") && e.contains("/dev/zero") && e.contains("not a regular file"),
            "{e}"
        );
        // A name that is not UTF-8 once decoded is an error, not a panic.
        let e = refused("bad-uri.gltf", tetra_gltf("%FF.bin").0);
        assert!(e.contains("not UTF-8"), "{e}");
        // A node that is its own child, and a stride shorter than a vertex: refused, not a
        // stack overflow or the importer's assertion.
        let cycle = json.replace(
            r#""nodes":[{"mesh":0}]"#,
            r#""nodes":[{"mesh":0,"children":[0]}]"#,
        );
        assert_ne!(cycle, json);
        let e = refused("cycle.gltf", cycle);
        assert!(e.contains("node 0 is reached twice"), "{e}");
        let stride = json.replace(
            r#"{"buffer":0,"byteLength":48}"#,
            r#"{"buffer":0,"byteLength":48,"byteStride":4}"#,
        );
        assert_ne!(stride, json);
        let e = refused("stride.gltf", stride);
        assert!(
            e.contains("byteStride 4 is less than its 12-byte element"),
            "{e}"
        );
        // A buffer shorter than the glTF says is named for it.
        std::fs::write(p.join("short.bin"), &bin[..40]).unwrap();
        let e = refused("short.gltf", tetra_gltf("short.bin").0);
        assert!(e.contains("buffer 0 has 40 bytes, the glTF says 72"), "{e}");
        // An accessor reaching past its view was read as no triangles; u8 positions were
        // read as floats.
        let past = json.replace(r#""count":4,"type":"VEC3""#, r#""count":5,"type":"VEC3""#);
        assert_ne!(past, json);
        let e = refused("past.gltf", past);
        assert!(
            e.contains("accessor 0 needs 60 bytes of buffer view 0"),
            "{e}"
        );
        let bytes = json.replace(r#""componentType":5126"#, r#""componentType":5121"#);
        assert_ne!(bytes, json);
        let e = refused("u8.gltf", bytes);
        assert!(
            e.contains("POSITION is Vec3 U8, expected VEC3 of FLOAT"),
            "{e}"
        );
        // Float indices reached the importer's unreachable code.
        let floats = json.replace(r#""componentType":5123"#, r#""componentType":5126"#);
        assert_ne!(floats, json);
        let e = refused("float-indices.gltf", floats);
        assert!(e.contains("indices are Scalar F32"), "{e}");
        // An OBJ that is not text says where.
        let binary = p.join("binary.obj");
        std::fs::write(&binary, b"v 0 0 0\nv 1 0 0\n\xff\xfe\x00garbage").unwrap();
        let e = load(&binary).unwrap_err().to_string();
        assert!(e.contains("line 3 is not UTF-8 text"), "{e}");
    }
}
