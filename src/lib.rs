//! EHA drain-oil thermal protection core (`#![no_std]`).
#![no_std]

pub mod protocol;
