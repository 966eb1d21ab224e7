//! Simulation layer: the physics integrated in time.
//!
//! - [`model`]: the right-hand side (thermal and hydraulic states);
//! - [`plant`]: the stiff solver and its drives (paper cases, missions,
//!   replay of logged inputs);
//! - [`scenario`], [`missions`]: the paper's cases and mission profiles;
//! - [`sim`]: runs and their outputs (shared log format plus internal
//!   channels);
//! - [`equilibrium`]: the steady state of the node balances (Newton);
//! - [`replay`]: a measured log's inputs as a replay scenario.

pub mod equilibrium;
pub mod fast;
pub mod missions;
pub mod model;
pub mod plant;
pub mod replay;
pub mod scenario;
pub mod sim;
