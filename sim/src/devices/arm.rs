//! The simulated arm: straight-line Cartesian moves of the tactile pad with speed and
//! acceleration limits (trapezoidal profile), advancing the simulated clock, inside a
//! workspace box and refusing moves that would crush an object.

use crate::contact::pad::{deepest_touch, pad_of};
use crate::world::SharedWorld;
use tactex_core::devices::{Arm, DeviceError};
use tactex_core::geometry::Pose;
use tactex_core::scene::Table;
use tactex_core::tactile::spec::TactileSpec;

pub struct SimArm {
    world: SharedWorld,
    spec: TactileSpec,
    pub max_speed_m_s: f64,
    pub max_accel_m_s2: f64,
    /// Workspace box (m): the table's extent, from the table surface up to `max_z_m`.
    pub max_z_m: f64,
    /// Refuse moves that push the pad further than this past first touch (mm).
    pub max_approach_mm: f64,
}

impl SimArm {
    pub fn new(world: SharedWorld, spec: TactileSpec) -> Self {
        Self {
            world,
            spec,
            max_speed_m_s: 0.5,
            max_accel_m_s2: 1.5,
            max_z_m: 0.6,
            max_approach_mm: 8.0,
        }
    }

    fn refuse(&self, reason: String) -> DeviceError {
        DeviceError::UnsafeMove {
            device: self.name().into(),
            reason,
        }
    }

    /// Whether a move to `target` would be taken: inside the workspace, pressing nothing
    /// past the crush limit (hand-eye calibration plans its stations with it).
    pub fn reaches(&self, target: &Pose) -> bool {
        let world = self.world.lock().expect("world lock");
        self.in_workspace(&world.table, target.position)
            && deepest_touch(&world, target, &pad_of(&self.spec))
                .is_none_or(|c| c.approach_mm <= self.max_approach_mm)
    }

    /// The workspace box: over the table, from its surface up to `max_z_m`.
    fn in_workspace(&self, table: &Table, p: glam::DVec3) -> bool {
        let [hx, hy] = table.size_m.map(|s| s / 2.0);
        p.x.abs() <= hx && p.y.abs() <= hy && (0.0..=self.max_z_m).contains(&p.z)
    }

    /// Duration of a trapezoidal-profile move of `distance` at cruise `speed`.
    fn move_duration_s(&self, distance: f64, speed: f64) -> f64 {
        let v = speed.min(self.max_speed_m_s);
        let a = self.max_accel_m_s2;
        if distance <= v * v / a {
            2.0 * (distance / a).sqrt()
        } else {
            distance / v + v / a
        }
    }
}

impl Arm for SimArm {
    fn name(&self) -> &str {
        "sim-arm"
    }

    fn pose(&self) -> Result<Pose, DeviceError> {
        Ok(self.world.lock().expect("world lock").tool)
    }

    fn move_linear(&mut self, target: &Pose, speed_m_s: f64) -> Result<(), DeviceError> {
        if !(target.position.is_finite() && target.rotation.is_finite()) {
            return Err(self.refuse("target pose is not finite".into()));
        }
        if !(speed_m_s.is_finite() && speed_m_s > 0.0) {
            return Err(self.refuse(format!("speed {speed_m_s} m/s must be finite and positive")));
        }
        let mut world = self.world.lock().expect("world lock");
        let p = target.position;
        if !self.in_workspace(&world.table, p) {
            return Err(self.refuse(format!(
                "target ({:.3}, {:.3}, {:.3}) m is outside the workspace",
                p.x, p.y, p.z
            )));
        }
        if let Some(c) = deepest_touch(&world, target, &pad_of(&self.spec))
            && c.approach_mm > self.max_approach_mm
        {
            return Err(self.refuse(format!(
                "target presses {:.1} mm into the {} (limit {} mm)",
                c.approach_mm, world.objects[c.object].label, self.max_approach_mm
            )));
        }
        let distance = (p - world.tool.position).length();
        world.time_s += self.move_duration_s(distance, speed_m_s);
        world.tool = *target;
        Ok(())
    }

    /// Moves are simulated whole, so there is never one in flight to halt.
    fn stop(&mut self) -> Result<(), DeviceError> {
        Ok(())
    }

    fn sim_time_s(&self) -> Option<f64> {
        Some(self.world.lock().expect("world lock").time_s)
    }
}
