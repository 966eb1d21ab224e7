//! Calibration against the independent rig emulator.
