//! Statistical model checking glue: properties observed on simulated runs, judged by monitors.

pub mod load;
pub mod observe;
pub mod record;
pub mod result;
pub mod sched_fixed;
pub mod schedulers;
mod split;
pub mod study;
