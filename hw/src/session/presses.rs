//! The presses in a session: runs of tactile frames taken at one spot, each run starting at
//! its highest pose. The pipeline presses this way (a no-contact reference just above the
//! object, then one frame per step down), and so does anyone pressing by hand with an arm.

use super::format::TactileFrameRecord;

/// Frames whose pad positions lie within this of each other (x and y) share a spot.
const SAME_SPOT_M: f64 = 0.5e-3;
/// A frame more than this above the one before starts a new press at the same spot.
const RISE_M: f64 = 1e-6;

/// Indices into `frames` grouped into presses, in recording order; within a press the pad
/// only goes down.
pub fn press_runs(frames: &[TactileFrameRecord]) -> Vec<Vec<usize>> {
    let mut runs: Vec<Vec<usize>> = Vec::new();
    for (i, frame) in frames.iter().enumerate() {
        let p = frame.arm_pose.position;
        let continues = runs.last().is_some_and(|run| {
            let first = frames[run[0]].arm_pose.position;
            let last = frames[run[run.len() - 1]].arm_pose.position;
            (p.x - first.x).abs() <= SAME_SPOT_M
                && (p.y - first.y).abs() <= SAME_SPOT_M
                && p.z <= last.z + RISE_M
        });
        match runs.last_mut() {
            Some(run) if continues => run.push(i),
            _ => runs.push(vec![i]),
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use tactex_core::geometry::Pose;
    use tactex_core::glam::DVec3;

    fn at(x: f64, y: f64, z: f64) -> TactileFrameRecord {
        TactileFrameRecord {
            image: String::new(),
            timestamp_s: 0.0,
            arm_pose: Pose::tool_down(DVec3::new(x, y, z)),
        }
    }

    #[test]
    fn frames_split_where_the_pad_moves_sideways_or_rises() {
        let frames = [
            at(0.1, 0.0, 0.050),
            at(0.1, 0.0, 0.049),
            at(0.1, 0.0002, 0.048),
            // Another fruit.
            at(-0.1, 0.0, 0.040),
            at(-0.1, 0.0, 0.039),
            // Back up at the same spot: a second press there.
            at(-0.1, 0.0, 0.045),
        ];
        assert_eq!(
            press_runs(&frames),
            vec![vec![0, 1, 2], vec![3, 4], vec![5]]
        );
        assert!(press_runs(&[]).is_empty());
    }
}
