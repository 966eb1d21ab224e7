//! Physical calibration of the reference model to a user's logs (issues 17
//! and 18): one implementation used by `diagnose` (nuisance set) and by
//! `commission` (the commissioned rig).
//!
//! - [`set`]: the declared parameters, their physical bounds, priors and
//!   the single table mapping them onto rig fields;
//! - [`log`]: a measured log prepared for replay and scoring;
//! - [`fit`]: joint fit over several logs with prior rows, on the
//!   objective of [`residuals`], ended by the Gauss–Newton [`polish`];
//! - [`direct`]: the firmware model's own parameters fitted directly to
//!   the logs from a reduction, with [`replay`] (the reduced model on a
//!   log's inputs at the 10 ms tick);
//! - [`ident`]: identifiability (singular values, intervals, correlated
//!   pairs) and the one-operating-point warning;
//! - [`synthetic`]: logs generated from a rig (tests and examples);
//! - [`paper`]: the reference's own calibration to the paper's Table 4,
//!   Table 5 and Fig. 15 (`eha-sim calibrate`), with [`lsq`].

pub mod check;
pub mod cli;
pub mod commission;
pub mod direct;
pub mod envelope;
pub mod envelope_report;
pub mod eta_m;
pub mod fit;
pub mod ident;
pub mod log;
pub mod margin;
pub mod lsq;
pub mod paper;
pub mod paths;
pub mod polish;
pub mod region;
pub mod replay;
pub mod residuals;
pub mod set;
pub mod synthetic;
pub mod thinning;

pub use fit::{calibrate, CalError, CalOptions, Calibration, ParamResult, Status};
pub use log::{channel_errors, CalLog, ChannelError};
pub use set::{apply, ParamDef, PARAMS};
