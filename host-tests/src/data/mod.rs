//! Data layer, below everything else: the measured-data format (a bench
//! log's reader with file, line and column errors, and its writer), what a
//! logger does to a signal (noise, quantisation) and the PNG plots. It knows no physics, so every layer above can read and draw.

pub mod acquisition;
pub mod measured;
pub mod plot;
