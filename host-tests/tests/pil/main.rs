//! Processor-in-the-loop tests: the firmware ELF in QEMU against the host
//! build of the same code and the reference plant (frame protocol, fault
//! handling, golden transcript, closed loop).

mod equivalence;
mod fault_subset;
mod faults;
mod golden;
mod protocol;
mod readme;
mod scenarios;
mod valve_loop;
