//! Shared helpers for hindsight's workspace-level tests.
