//! Calibration set: recovery on synthetic
//! data of the reference, a truth written independently (the rig
//! emulator), and the one-operating-point warning.

mod cli;
mod commission;
mod direct;
mod emulator;
mod foreign;
mod like_ref;
mod mix_audit;
mod mix_structure;
mod recovery;
mod reduce_servo;
