//! Dense indices of machines, states and events in a [`super::CompiledModel`].

/// A machine: index into the model's machine list (folder order, or `model.xml` order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MachineId(pub u32);

/// A state of one machine: index into that machine's states (document order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct StateId(pub u32);

/// An event: index into the model's event list (order of first appearance).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EventId(pub u32);
