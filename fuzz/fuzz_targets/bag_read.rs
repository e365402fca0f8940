//! Fuzz target: any bytes as an MCAP file through `hindsight-ros2`'s recording reader and
//! the replay feed (schemas from the file's `ros2msg` texts, CDR decoding of the ports'
//! fields). It must give points or an error, never panic or allocate a claimed size.
#![no_main]

use hindsight_ros2::feed::{replay_mcap_bytes, Port, Read, TimeSource};
use hindsight_ros2::schema::BuiltinDefs;
use libfuzzer_sys::fuzz_target;
use monitor_core::Ty;

fuzz_target!(|data: &[u8]| {
    let ports = [
        Port {
            var: 0,
            ty: Ty::Int,
            topic: "/level".into(),
            read: Read::Field("data".into()),
            service: None,
            name: "level".into(),
        },
        Port {
            var: 1,
            ty: Ty::Float,
            topic: "/battery".into(),
            read: Read::Field("cell_voltage[0]".into()),
            service: None,
            name: "cell".into(),
        },
        Port {
            var: 2,
            ty: Ty::Bool,
            topic: "/battery".into(),
            read: Read::Event,
            service: None,
            name: "seen".into(),
        },
    ];
    let _ = replay_mcap_bytes(
        data,
        &ports,
        &BuiltinDefs::new(),
        TimeSource::Log,
        &[],
        &mut |_| Ok::<(), std::convert::Infallible>(()),
    );
});
