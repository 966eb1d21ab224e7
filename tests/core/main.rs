//! Host tests of the firmware core (`eha-guard` built for the host): the
//! reduced model's accuracy and discretisation, the protection layer's
//! properties (proptest), the over-temperature alarm and derate, and the
//! pump's flow bookkeeping in a pressure hold.

mod alarm;
mod crosscheck;
mod faulted_runs;
mod lng_credit;
mod margin;
mod model_accuracy;
mod plant;
mod protection_cases;
mod protection_props;
mod rate;
mod records;
mod servo_hold;
mod stall;
mod startup;
mod untrusted;
mod valve;
