//! How a run stops on a model error: a diagnostic at the failing instruction, or a spin report.

use super::*;

impl Simulator<'_> {
    pub(super) fn diag_error(&self, m: usize, pc: Option<usize>, e: EvalError) -> Stop {
        let def = &self.model.machines[m];
        let span = if e.at != 0 {
            def.file.at(e.at)
        } else {
            pc.and_then(|p| def.code_spans.get(p).copied())
                .unwrap_or(def.file.at(0))
        };
        Stop::End(Box::new(EndReason::Error(RunError {
            machine: MachineId(m as u32),
            time: self.time,
            diagnostic: self.model.sources.diag(span, message(&e)),
        })))
    }

    pub(super) fn spin(&self, m: usize, kind: SpinKind) -> Stop {
        let def = &self.model.machines[m];
        let s = self.ms[m].state;
        let state_name = def
            .states
            .get(s as usize)
            .map_or(String::new(), |st| st.name.clone());
        let span = def
            .states
            .get(s as usize)
            .map(|st| st.span)
            .unwrap_or(def.file.at(0));
        Stop::End(Box::new(EndReason::Spin(SpinReport {
            kind,
            machine: MachineId(m as u32),
            state: StateId(s),
            machine_name: def.name.clone(),
            state_name: state_name.clone(),
            location: self
                .model
                .sources
                .diag(span, format!("state `{state_name}`")),
        })))
    }

    pub(super) fn internal(&self, m: usize, pc: u32) -> Stop {
        self.diag_error(
            m,
            Some(pc as usize),
            EvalError {
                at: 0,
                kind: EvalErrorKind::Internal,
            },
        )
    }
}

/// What a run-time error says: a delay between two time units in durations as the model
/// wrote them (`150ms`, `100ms`; the expression language knows no units).
fn message(e: &EvalError) -> String {
    match e.kind {
        EvalErrorKind::DelaySteps { ns, unit } => format!(
            "a delay of {} is not a whole number of model time units of {}",
            codegen::duration::format(ns),
            codegen::duration::format(unit)
        ),
        _ => e.message(),
    }
}
