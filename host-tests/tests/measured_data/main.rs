//! The strict reader and writer of the shared measured-data format.

mod reader;
