//! Why the sidecar, a paced run or one of their ports failed: [`LiveError`], the one
//! error type of this crate's I/O (iceoryx2, DDS, outputs), with what names the fault.

/// Why the sidecar, a paced run or one of their ports could not run.
#[derive(Debug)]
pub enum LiveError {
    /// iceoryx2 refused a node, service or port.
    Ipc {
        /// What was asked for: `node`, a service's name, `service name `NAME``.
        at: String,
        /// iceoryx2's reason.
        reason: String,
    },
    /// Writing an output failed.
    Io(std::io::Error),
    /// Writing the MCAP recording (`monitor --ros2 --record`) failed.
    Mcap(ros2::write::WriteError),
    /// The benchmark's own spec or config does not compile (a bug: [`mod@crate::bench`]).
    Spec(codegen::Diagnostics),
    /// The DDS participant, a reader or a writer could not be created.
    Dds(ros2::dds::DdsError),
    /// A service served on DDS whose type does not resolve (`run --ros2 --external`).
    Service {
        /// The ROS service.
        service: String,
        /// Why its request or response type does not resolve.
        error: ros2::schema::SchemaError,
    },
    /// The monitors of the spec could not be built (a compiler bug).
    Engine(crate::engine::EngineError),
    /// The engine rejected a point (a bug: the config checks types).
    Record(crate::record::RecordError),
    /// A benchmark's thread failed (`bench`): what it was.
    Thread(&'static str),
}

impl LiveError {
    /// iceoryx2's refusal of `at`, its reason as iceoryx2 spells it.
    pub(crate) fn ipc(at: impl Into<String>, reason: impl std::fmt::Debug) -> LiveError {
        LiveError::Ipc {
            at: at.into(),
            reason: format!("{reason:?}"),
        }
    }
}

impl std::fmt::Display for LiveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LiveError::Ipc { at, reason } => write!(f, "iceoryx2: {at}: {reason}"),
            LiveError::Io(e) => write!(f, "output: {e}"),
            LiveError::Mcap(e) => write!(f, "output: {e}"),
            LiveError::Spec(d) => write!(f, "{d}"),
            LiveError::Dds(e) => write!(f, "{e}"),
            LiveError::Service { service, error } => write!(f, "service {service}: {error}"),
            LiveError::Engine(e) => write!(f, "monitor: {e}"),
            LiveError::Record(e) => write!(f, "monitor: {e}"),
            LiveError::Thread(what) => write!(f, "{what} panicked"),
        }
    }
}

impl std::error::Error for LiveError {}

impl From<std::io::Error> for LiveError {
    fn from(e: std::io::Error) -> LiveError {
        LiveError::Io(e)
    }
}

/// For `map_err`: iceoryx2's refusal of `what` as a [`LiveError::Ipc`].
pub(crate) fn ipc<E: std::fmt::Debug>(what: &str) -> impl Fn(E) -> LiveError + '_ {
    move |e| LiveError::ipc(what, e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_what_failed_and_why() {
        #[derive(Debug)]
        enum Refused {
            ServiceInCorruptedState,
        }
        let e = LiveError::ipc("museum/battery", Refused::ServiceInCorruptedState);
        assert_eq!(
            e.to_string(),
            "iceoryx2: museum/battery: ServiceInCorruptedState"
        );
        let e = LiveError::Engine(crate::engine::EngineError(monitor_core::TableError::Decode));
        assert!(
            e.to_string()
                .starts_with("monitor: internal: compiled program rejected: "),
            "{e}"
        );
        let e = LiveError::from(std::io::Error::other("disk full"));
        assert_eq!(e.to_string(), "output: disk full");
    }
}
