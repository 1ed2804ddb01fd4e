//! tactex-hw's integration tests, one module per device or format, in one test binary.

mod devices_file;
mod gelsight_mini_frames;
mod session_files;
mod v4l2_devices;
mod xarm_fake_controller;
