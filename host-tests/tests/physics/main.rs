//! Physics tests of the reference simulation: the paper's published numbers,
//! energy closure and the stiff solver against analytic solutions.

mod energy;
mod fast;
mod paper;
mod pump_energy;
mod solver;
mod uq;
