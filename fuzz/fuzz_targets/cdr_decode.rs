//! Fuzz target: any bytes as a serialised `sensor_msgs/BatteryState` (nested header,
//! strings, sequences, fixed-size fields) through `hindsight-ros2`'s CDR decoder, with
//! fields selected in nested messages and inside sequences. It must return a value or an
//! error, never panic, and never allocate for a length it read.
#![no_main]

use std::sync::OnceLock;

use hindsight_ros2::cdr::Decoder;
use hindsight_ros2::schema::{BuiltinDefs, Schema};
use libfuzzer_sys::fuzz_target;
use monitor_core::{Ty, Value};

fn decoder() -> &'static Decoder {
    static D: OnceLock<Decoder> = OnceLock::new();
    D.get_or_init(|| {
        let schema = Schema::resolve("sensor_msgs/msg/BatteryState", &BuiltinDefs::new())
            .expect("built-in type");
        let mut d = Decoder::new(schema, &["base".to_string()]);
        for (path, ty) in [
            ("header.stamp.sec", Ty::Int),
            ("header.frame_id", Ty::Str),
            ("percentage", Ty::Float),
            ("present", Ty::Bool),
            ("cell_voltage[2]", Ty::Float),
            ("serial_number", Ty::Str),
        ] {
            d.add(path, ty).expect("a field of BatteryState");
        }
        d
    })
}

fuzz_target!(|data: &[u8]| {
    let d = decoder();
    let mut out = vec![Value::Bool(false); d.slots()];
    let mut present = vec![false; d.slots()];
    let _ = d.decode(data, &mut out, &mut present);
});
