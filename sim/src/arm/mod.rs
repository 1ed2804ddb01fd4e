//! The robot arm as a kinematic chain: what the twin needs to answer a controller's joint
//! commands as the real one does. `uf850` is the UFACTORY 850 (xArm 850), the arm the paper
//! presses with: forward kinematics from the maker's published modified D-H parameters,
//! inverse kinematics by damped least squares from the current joints (the branch nearest
//! to them, as the controller chooses), joint limits.

pub mod uf850;
