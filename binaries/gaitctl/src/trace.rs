//! `gaitctl trace mcap TRACE -o FILE.mcap`: a `gait-trajectory/1` trace as
//! an MCAP recording for Foxglove, the ROS 2 bag tools and Rerun (the
//! channels: docs/design/10-traces.md, "MCAP"). `gaitctl plot` reads the
//! recording as it reads the trace.

use std::io::{BufRead, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `gaitctl trace`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(clap::Subcommand, Debug)]
enum Cmd {
    /// Convert a trace (gait-trajectory/1, JSON lines) to an MCAP recording:
    /// channels /gaitd/header, /gaitd/sample (the lines, JSON), /gaitd/tf and
    /// /gaitd/scene (Foxglove's 3D panel); log times are the samples' t.
    Mcap(McapArgs),
}

/// Arguments of `gaitctl trace mcap`.
#[derive(clap::Args, Debug)]
struct McapArgs {
    /// The trace (gait-trajectory/1, JSON lines).
    trace: PathBuf,
    /// The recording to write (.mcap).
    #[arg(long, short = 'o', value_name = "FILE")]
    out: PathBuf,
}

/// Writes the trace read from `trace` to the file `out` as MCAP; on an
/// error removes the partial file.
pub fn write_mcap(trace: impl BufRead, out: &Path) -> Result<trace_mcap::Written, String> {
    let file =
        std::fs::File::create(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut file = BufWriter::new(file);
    let r = trace_mcap::write(trace, &mut file).and_then(|w| Ok(file.flush().map(|()| w)?));
    r.map_err(|e| {
        // A partial recording would look like a short trace.
        drop(file);
        let _ = std::fs::remove_file(out);
        e.to_string()
    })
}

fn mcap(a: &McapArgs) -> Result<ExitCode, String> {
    let clock = Instant::now();
    let input = std::fs::File::open(&a.trace)
        .map_err(|e| format!("cannot open {}: {e}", a.trace.display()))?;
    let mut input = std::io::BufReader::new(input);
    let prefix = input
        .fill_buf()
        .map_err(|e| format!("{}: {e}", a.trace.display()))?;
    if trace_mcap::is_mcap(prefix) {
        return Err(format!(
            "{}: already an MCAP recording (give the JSON-lines trace)",
            a.trace.display()
        ));
    }
    let w = write_mcap(input, &a.out).map_err(|e| format!("{}: {e}", a.trace.display()))?;
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    println!(
        "{} samples, {:.2} s, {} messages; {} → {} bytes in {:.0} ms → {}",
        w.samples,
        (w.end_ns - w.start_ns) as f64 * 1e-9,
        w.messages,
        size(&a.trace),
        size(&a.out),
        clock.elapsed().as_secs_f64() * 1e3,
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Runs `gaitctl trace`.
pub fn run(a: &Args) -> Result<ExitCode, String> {
    match &a.cmd {
        Cmd::Mcap(m) => mcap(m),
    }
}
