//! The firmware's reduced model (host build of `eha-guard`) in closed loop
//! with the reference simulation.

mod faults;
mod nv_wear;
mod rest_cooling;
mod vs_reference;
