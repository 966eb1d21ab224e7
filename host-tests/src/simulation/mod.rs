//! Simulation layer: the physics integrated in time.
//!
//! - [`model`]: the right-hand side (thermal and hydraulic states);
//! - [`plant`]: the stiff solver and its drives (paper cases, missions,
//!   replay of logged inputs);
//! - [`scenario`], [`missions`]: the paper's cases and mission profiles;
//! - [`sim`]: runs and their outputs (shared log format plus internal
//!   channels);
//! - [`equilibrium`]: the steady state of the node balances (Newton);
//! - [`replay`]: a measured log's inputs as a replay scenario;
//! - [`grids`]: the outer surfaces' heat flows and the oil's viscosity
//!   interpolated on a temperature grid (the fast plant's heat balances).

pub mod equilibrium;
pub mod fast;
pub mod grids;
pub mod missions;
pub mod model;
mod outer_memo;
pub mod plant;
pub mod replay;
pub mod scenario;
pub mod sim;
