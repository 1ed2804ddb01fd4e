//! NumPy archives (.npz) as `numpy.savez_compressed` writes them: a zip of `.npy` arrays
//! (format 1.0, C order), deflated, with fixed timestamps so the same data gives the same bytes.

use anyhow::{Context, Result};
use std::io::{Cursor, Write};
use zip::write::SimpleFileOptions;

/// One array of an archive: its name, dtype descriptor ('|u1', '<f4', '<f8'), shape and
/// little-endian bytes.
pub struct NpyArray<'a> {
    pub name: &'a str,
    pub descr: &'static str,
    pub shape: Vec<usize>,
    pub data: Vec<u8>,
}

impl<'a> NpyArray<'a> {
    pub fn u8(name: &'a str, shape: Vec<usize>, data: Vec<u8>) -> Self {
        Self {
            name,
            descr: "|u1",
            shape,
            data,
        }
    }

    pub fn f32(name: &'a str, shape: Vec<usize>, data: &[f32]) -> Self {
        Self {
            name,
            descr: "<f4",
            shape,
            data: data.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }

    pub fn f64(name: &'a str, shape: Vec<usize>, data: &[f64]) -> Self {
        Self {
            name,
            descr: "<f8",
            shape,
            data: data.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }

    /// The array as a `.npy` file.
    fn npy(&self) -> Vec<u8> {
        let shape = match self.shape.len() {
            1 => format!("({},)", self.shape[0]),
            _ => format!(
                "({})",
                self.shape
                    .iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        let mut header = format!(
            "{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}",
            self.descr
        );
        // Magic (6) + version (2) + length (2) + header + '\n' is padded to 64 bytes.
        let unpadded = 10 + header.len() + 1;
        header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
        header.push('\n');
        let mut out = Vec::with_capacity(10 + header.len() + self.data.len());
        out.extend_from_slice(b"\x93NUMPY\x01\x00");
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(&self.data);
        out
    }
}

/// The archive's bytes.
pub fn npz_bytes(arrays: &[NpyArray]) -> Result<Vec<u8>> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    for a in arrays {
        let expected = a.shape.iter().product::<usize>()
            * match a.descr {
                "|u1" => 1,
                "<f4" => 4,
                _ => 8,
            };
        anyhow::ensure!(
            a.data.len() == expected,
            "array {}: {} bytes for shape {:?}",
            a.name,
            a.data.len(),
            a.shape
        );
        zip.start_file(format!("{}.npy", a.name), options)
            .context("npz: starting an entry")?;
        zip.write_all(&a.npy()).context("npz: writing an entry")?;
    }
    Ok(zip.finish().context("npz: finishing")?.into_inner())
}
