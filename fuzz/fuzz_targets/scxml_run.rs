//! Fuzz target: any bytes as up to three plain SCXML machines (split at NUL bytes), read,
//! compiled and run from two seeds under both event semantics (SCAN's queues, AS2FM's
//! pending events) and a sampled scheduler. It must give a run or an error, never panic.
//! Faster than `model_file` (no files, no property compiler), so it reaches deeper into
//! the expression language and the simulator.
#![no_main]

use hindsight_verify::model::ModelSource;
use hindsight_verify::sim::{
    CompiledModel, EventSemantics, Memory, PutBack, RunConfig, Sampled, Scheduler, Simulator,
    TraceRecorder,
};
use libfuzzer_sys::fuzz_target;
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

const NAMES: [&str; 3] = ["a.scxml", "b.scxml", "c.scxml"];

fuzz_target!(|data: &[u8]| {
    // Not UTF-8: the file reader's error, tested elsewhere; here every input is text.
    let text = String::from_utf8_lossy(data);
    let files = NAMES.iter().copied().zip(text.split('\0'));
    let Ok(source) = ModelSource::from_texts(files) else {
        return;
    };
    let Ok(model) = CompiledModel::compile(source) else {
        return;
    };
    let mut sim = Simulator::new(&model);
    let schedulers = [
        Scheduler::Uniform,
        Scheduler::Sampled(Sampled {
            id: 7,
            memory: Memory::History,
            uniform: PutBack::default(),
        }),
    ];
    for events in [EventSemantics::Queues, EventSemantics::As2fm] {
        for (seed, scheduler) in schedulers.into_iter().enumerate() {
            let cfg = RunConfig {
                max_time: 20,
                max_steps: 2_000,
                max_steps_per_instant: 500,
                events,
                scheduler,
                ..RunConfig::default()
            };
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed as u64);
            let mut trace = TraceRecorder::new();
            let _ = sim.run(&mut rng, &cfg, &mut trace);
        }
    }
});
