//! Running a firmware image under `qemu-system-arm` with semihosting, with a time limit.

use std::io::Read;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

/// The QEMU binary (Debian's `qemu-system-arm`).
pub const QEMU: &str = "qemu-system-arm";

/// What one QEMU run produced.
#[derive(Debug)]
pub struct Run {
    /// Everything the firmware wrote to semihosting stdout: the raw defmt stream.
    pub stdout: Vec<u8>,
    /// QEMU's stderr, for error messages.
    pub stderr: String,
    /// QEMU's exit status: the firmware's semihosting exit code.
    pub status: ExitStatus,
    /// Wall-clock time of the run.
    pub elapsed: Duration,
}

/// The QEMU command line for `image` on the board of `$FIRMWARE_TARGET`
/// ([`crate::board`]): semihosting on, no display.
pub fn command(image: &Path) -> Result<Command, String> {
    let board = crate::board()?;
    let mut cmd = Command::new(QEMU);
    if let Some(cpu) = board.cpu {
        cmd.args(["-cpu", cpu]);
    }
    cmd.args([
        "-machine",
        board.machine,
        "-nographic",
        "-semihosting-config",
        "enable=on,target=native",
        "-kernel",
    ])
    .arg(image);
    Ok(cmd)
}

/// Boots `image` and waits for it to exit; an image still running after
/// `timeout` is killed and reported as an error.
pub fn run(image: &Path, timeout: Duration) -> Result<Run, String> {
    let start = Instant::now();
    let mut child = command(image)?
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {QEMU}: {e} (apt-get install qemu-system-arm)"))?;
    let mut out = child.stdout.take().ok_or("no stdout pipe")?;
    let mut err = child.stderr.take().ok_or("no stderr pipe")?;
    let out_reader = thread::spawn(move || {
        let mut buf = Vec::new();
        out.read_to_end(&mut buf).map(|_| buf)
    });
    let err_reader = thread::spawn(move || {
        let mut buf = String::new();
        err.read_to_string(&mut buf).map(|_| buf)
    });
    let status = loop {
        match child
            .try_wait()
            .map_err(|e| format!("waiting for {QEMU}: {e}"))?
        {
            Some(status) => break status,
            None if start.elapsed() > timeout => {
                // Best effort: the child may exit between the check and the kill.
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!(
                    "{} did not exit within {timeout:?}",
                    image.display()
                ));
            }
            None => thread::sleep(Duration::from_millis(5)),
        }
    };
    let stdout = out_reader
        .join()
        .map_err(|_| "stdout reader panicked")?
        .map_err(|e| format!("reading QEMU stdout: {e}"))?;
    let stderr = err_reader
        .join()
        .map_err(|_| "stderr reader panicked")?
        .map_err(|e| format!("reading QEMU stderr: {e}"))?;
    Ok(Run {
        stdout,
        stderr,
        status,
        elapsed: start.elapsed(),
    })
}
