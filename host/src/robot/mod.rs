//! Robot models read natively: AS2FM's high-level format (main file, BehaviorTree.cpp tree,
//! SCXML with ROS 2 tags, ROS interfaces, JANI properties) lowered to plain SCXML.
//!
//! # Pipeline
//!
//! 1. `main_file`: the main file (`<roaml>`, or the older `<convince_mc_tc>`) names the
//!    tree, its plugins, the node models, data types and properties, and the parameters
//!    (`max_time`, `bt_tick_rate`, ...).
//! 2. [`bt`]: the behavior tree and its plugins become machines (one per tree node, plus the
//!    root that ticks the tree and the blackboard); what is left of them is SCXML with ROS
//!    tags. [`bt::lower`] takes a [`bt::BtInput`] (tree file, plugin files, tick rate).
//! 3. `ros`: every machine's ROS tags (timers, topics, services, actions) become plain
//!    SCXML sends and transitions; generated machines (the global timer, service and
//!    action handlers) are added. `interfaces` gives the message layouts.
//! 4. The plain machines are read by [`crate::model`] from the element trees (spans still
//!    point into the files the user wrote), so the simulator sees the same model that
//!    `hindsight convert` writes with [`write::to_xml`].
//!
//! Element trees are [`crate::model::xml::Element`]: every element and attribute keeps the
//! span of the source it was made from, so errors found late name the user's file.

pub mod bt;
pub mod datatypes;
pub mod interfaces;
pub mod load;
pub mod main_file;
mod main_ignored;
#[cfg(test)]
mod random_text;
pub mod rate;
pub mod ros;
pub mod types;
pub mod write;
