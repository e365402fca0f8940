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
//!
//! # Crate
//!
//! `hindsight-robot` depends on `codegen` (source map, diagnostics, durations, scalar
//! names), `hindsight-ros2` (interface definitions), `hindsight-expr` and `hindsight-sim`
//! (re-exported here as [`expr`], [`model`] and [`sim`], the paths this crate's modules
//! name them by), on no other crate of the project; `hindsight`'s `verify` loads robot
//! models through [`load`], and `hindsight convert` writes them with [`write::to_xml`].
//!
//! A tree lowered in memory to its machines (SCXML with ROS tags, which [`ros`] lowers
//! next), written as `hindsight convert` writes it, and a refused node named at its file
//! position:
//!
//! ```
//! use hindsight_robot::bt::{self, BtInput};
//! use hindsight_robot::model::source::SourceMap;
//! use hindsight_robot::model::Diagnostics;
//!
//! let tree = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
//!   <BehaviorTree ID="Main">
//!     <Sequence><AlwaysSuccess/><Inverter><AlwaysFailure/></Inverter></Sequence>
//!   </BehaviorTree>
//! </root>"#;
//! let mut sm = SourceMap::new();
//! let input = BtInput {
//!     tree: sm.add("tree.xml", tree.to_string()),
//!     plugins: vec![],
//!     tick_rate_hz: 10.0,
//!     tick_if_not_running: true,
//!     halts: Default::default(),
//!     semantics: Default::default(),
//! };
//! let machines = bt::lower(&sm, &input).unwrap();
//! assert_eq!(machines[0].attr_value("name"), Some("bt_root_fsm_tree"));
//! assert!(machines.len() >= 5, "the root and one machine per node");
//! let xml = hindsight_robot::write::to_xml(&machines[0]);
//! assert!(xml.contains("bt_root_fsm_tree"), "{xml}");
//!
//! // A leaf with no plugin is refused at its line and column.
//! let mut sm = SourceMap::new();
//! let tree = r#"<root BTCPP_format="4"><BehaviorTree ID="Main">
//!   <Action ID="Dock"/></BehaviorTree></root>"#;
//! let input = BtInput { tree: sm.add("tree.xml", tree.to_string()), ..input };
//! let errs = Diagnostics(bt::lower(&sm, &input).unwrap_err());
//! assert!(errs.to_string().starts_with("tree.xml:2:15: unknown node `Dock`"), "{errs}");
//! ```

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

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

// The crates below this one, under the paths its modules name them by (`crate::model::…`,
// `crate::sim::…`, `crate::expr::…`), as `hindsight` re-exports them.
pub use hindsight_expr as expr;
pub use hindsight_sim::{model, sim};
