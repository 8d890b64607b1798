//! CLI errors: bad input (exit code 2) or failures while running (exit code 1).

use afmdyn::study::checkpoint::CheckpointError;
use thiserror::Error;

/// What can go wrong in a command.
#[derive(Debug, Error)]
pub enum CliError {
    /// Invalid flags, config or parameters: exit code 2.
    #[error("{0}")]
    Input(String),
    /// A computation failed, or the library refused an option (the message names the flag,
    /// see [`spell`]).
    #[error("{}", spell(.0))]
    Sim(#[from] afmdyn::error::SimError),
    /// Reading or writing a file failed; the message names the file (see
    /// [`afmdyn::layout::files::io_error`]). There is deliberately no conversion from `std::io::Error`,
    /// which would lose the path.
    #[error("{0}")]
    Io(String),
    /// SIGINT or SIGTERM ended the run (exit code 130).
    #[error("interrupted; the partial files of this run were removed")]
    Interrupted,
}

/// Set by the handler [`stop_on_signal`] installs.
static SIGNALLED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Catch SIGINT and SIGTERM (and SIGHUP) for a run that streams files with no resume
/// (`simulate`): the first signal asks it to stop at its next check ([`interrupted`]), so that
/// its partial files are removed on the way out; a second one exits at once (130).
pub fn stop_on_signal() {
    let _ = ctrlc::set_handler(|| {
        if SIGNALLED.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
}

/// [`CliError::Interrupted`] once a signal arrived ([`stop_on_signal`]).
pub fn interrupted() -> Result<(), CliError> {
    if SIGNALLED.load(std::sync::atomic::Ordering::SeqCst) {
        Err(CliError::Interrupted)
    } else {
        Ok(())
    }
}

/// The library's message with a request parameter spelled as its flag: `samples_per_period`
/// → `samples-per-period`, `initial` → `--initial-modal`; the hints of a budget name the
/// flags that lower it, those of an unsupported integrator the `--integrator` flag.
pub fn spell(e: &afmdyn::error::SimError) -> String {
    let msg = e.spelled(|name| match name {
        "initial" => "--initial-modal".to_string(),
        // a probe file's key ([section].key) keeps its TOML spelling
        _ if name.starts_with('[') => name.to_string(),
        _ => name.replace('_', "-"),
    });
    match e {
        afmdyn::error::SimError::Budget { .. } => msg
            .replace("lower periods", "lower --periods")
            .replace("samples_per_period", "--samples-per-period")
            .replace("keep no time series", "use --files none"),
        // `use integrator = "adaptive" (or "auto")` → `use --integrator adaptive (or auto)`
        afmdyn::error::SimError::Unsupported { .. } => msg
            .replace("integrator = ", "--integrator ")
            .replace('"', ""),
        _ => msg,
    }
}

impl CliError {
    /// Process exit code.
    pub fn code(&self) -> i32 {
        match self {
            CliError::Input(_) => 2,
            CliError::Sim(e) if e.is_input_error() => 2,
            CliError::Sim(_) => 1,
            CliError::Io(_) => 1,
            CliError::Interrupted => 130,
        }
    }
}

/// The command line's message for a checkpoint error (`--resume` names the flag) of a store of
/// `what` (`sweep`, `chart`) results.
pub(crate) fn store_error(e: CheckpointError, what: &str) -> CliError {
    match e {
        CheckpointError::Io { .. } => CliError::Io(e.to_string()),
        CheckpointError::Mismatch { field, then, now } => CliError::Input(format!(
            "--resume: {} = {then} in the interrupted run, {now} now; rerun with the same \
             arguments, or without --resume to start over",
            field.replace('_', "-")
        )),
        CheckpointError::Unrecorded { store, ledger } => CliError::Input(format!(
            "--resume: {store} has {what} results but no record of the arguments that made them \
             ({ledger} is missing); rerun without --resume to start over"
        )),
        CheckpointError::Corrupt { .. } => CliError::Input(e.to_string()),
    }
}

/// The command line's message for a study that stopped ([`store_error`] for its store).
pub(crate) fn study_error(e: afmdyn::study::StudyError, what: &str) -> CliError {
    match e {
        afmdyn::study::StudyError::Store(e) => store_error(e, what),
        afmdyn::study::StudyError::Sim(e) => CliError::Sim(e),
    }
}

impl From<afmdyn::error::ParamError> for CliError {
    fn from(e: afmdyn::error::ParamError) -> Self {
        CliError::Input(e.to_string())
    }
}

impl From<afmdyn::probe::ProbeError> for CliError {
    fn from(e: afmdyn::probe::ProbeError) -> Self {
        CliError::Input(format!("probe {e}"))
    }
}

impl From<afmdyn::error::UnitsError> for CliError {
    fn from(e: afmdyn::error::UnitsError) -> Self {
        CliError::Input(e.to_string())
    }
}

impl From<afmdyn::layout::files::FileError> for CliError {
    fn from(e: afmdyn::layout::files::FileError) -> Self {
        CliError::Io(e.0)
    }
}

impl From<crate::plot::PlotError> for CliError {
    fn from(e: crate::plot::PlotError) -> Self {
        match e {
            crate::plot::PlotError::File(e) => e.into(),
            // a store's table not as written, or past its cap: the input's fault (exit code 2)
            crate::plot::PlotError::Feed(afmdyn::layout::figure::FeedError::Refused(m)) => {
                CliError::Input(m)
            }
            e => CliError::Io(e.to_string()),
        }
    }
}
