//! Statistical model checking glue: properties observed on simulated runs, judged by monitors.

pub mod observe;
pub mod settle;
