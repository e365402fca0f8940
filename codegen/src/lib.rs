//! hindsight's specification language: Past-MTL formulas over typed atoms, compiled to monitors.
pub mod emit_rust;
