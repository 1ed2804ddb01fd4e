//! The twin's UF850 forward kinematics (modified D-H, sim/src/arm/uf850.rs) against an
//! independent computation from UFACTORY's standard D-H table for the same arm, read from
//! a fixture of the published document (tests/fixtures/uf850_standard_dh.toml).

use glam::{DMat4, DVec3};
use serde::Deserialize;
use tactex_sim::arm::uf850::{UF850_LIMITS_RAD, forward};

#[derive(Deserialize)]
struct Table {
    joint: Vec<StandardDh>,
}

#[derive(Deserialize)]
struct StandardDh {
    theta_offset_deg: f64,
    d_mm: f64,
    alpha_deg: f64,
    a_mm: f64,
}

fn standard_forward(table: &Table, q: [f64; 6]) -> DMat4 {
    table
        .joint
        .iter()
        .zip(q)
        .fold(DMat4::IDENTITY, |t, (row, qi)| {
            t * DMat4::from_rotation_z(qi + row.theta_offset_deg.to_radians())
                * DMat4::from_translation(DVec3::new(0.0, 0.0, row.d_mm))
                * DMat4::from_translation(DVec3::new(row.a_mm, 0.0, 0.0))
                * DMat4::from_rotation_x(row.alpha_deg.to_radians())
        })
}

#[test]
fn forward_kinematics_agrees_with_the_published_standard_table_at_100_configurations() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/uf850_standard_dh.toml"
    );
    let table: Table = toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(table.joint.len(), 6);
    let mut state = 7u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..100 {
        let q: [f64; 6] = std::array::from_fn(|i| {
            let [lo, hi] = UF850_LIMITS_RAD[i];
            lo + (hi - lo) * uniform()
        });
        let twin = forward(q);
        let reference = standard_forward(&table, q);
        let position_err = (twin.position_mm - reference.w_axis.truncate()).length();
        assert!(position_err < 0.1, "{q:?}: {position_err} mm");
        // The angle of the rotation between the two flange frames.
        let r = twin.rotation.transpose() * glam::DMat3::from_mat4(reference);
        let cos = ((r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0) / 2.0).clamp(-1.0, 1.0);
        assert!(
            cos.acos().to_degrees() < 0.01,
            "{q:?}: {} degrees",
            cos.acos().to_degrees()
        );
    }
}
