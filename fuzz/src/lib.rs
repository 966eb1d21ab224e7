//! Shared harness code of the fuzz targets (`fuzz_targets/*.rs`): the
//! structured guard-op interpreter ([`guard`]), the link/protocol driver
//! ([`link`]) and the run statistics printed at exit ([`stats`]).

pub mod guard;
pub mod link;
pub mod stats;
