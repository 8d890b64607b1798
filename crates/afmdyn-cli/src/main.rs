//! `afmdyn` — command-line interface: parse flags, call the library, write outputs.

/// `println!` that does not panic: a failed write to standard output returns
/// [`CliError::Io`] naming it from the enclosing function ([`output::write_stdout`]).
macro_rules! outln {
    () => {
        $crate::output::write_stdout(format_args!("\n"))?
    };
    ($($t:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($t)*)))?
    };
}

/// `print!` that does not panic ([`outln!`]).
#[allow(unused_macros)]
macro_rules! out {
    ($($t:tt)*) => {
        $crate::output::write_stdout(format_args!($($t)*))?
    };
}

/// `eprintln!` that does not panic: a failed write to standard error returns
/// [`CliError::Io`] ([`output::write_stderr`]).
macro_rules! errln {
    ($($t:tt)*) => {
        $crate::output::write_stderr(format_args!("{}\n", format_args!($($t)*)))?
    };
}

mod args;
mod cmd_analysis;
mod cmd_approach;
mod cmd_basins;
mod cmd_chart;
mod cmd_fit;
mod cmd_fm;
mod cmd_image;
mod cmd_modes;
mod cmd_orbits;
mod cmd_peakforce;
mod cmd_reconstruct;
mod cmd_simulate;
mod door;
mod error;
mod output;
use afmdyn_plot as plot;
mod progress;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use error::CliError;
use std::io::Write;

/// Multi-modal tapping-mode AFM dynamics with intermittent contact.
#[derive(Debug, Parser)]
#[command(
    name = "afmdyn",
    version,
    about,
    after_help = "Output files, their columns and units, the input limits and the exit codes \
                  (0 done, 1 failed, 2 bad input) are documented in docs/outputs.md; every .npy \
                  comes with a .npy.json naming its columns."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Display units of text and plots in SI runs (--probe): afm (prefixed: nm, pN, kHz, aJ)
    /// or si (plain m, N, Hz, J). Data files and JSON are always in plain SI
    #[arg(long, value_enum, global = true, default_value = "afm")]
    units: output::DisplayUnits,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Natural frequencies and damped eigenvalues of the free and contact systems (eqs. 19–23)
    Modes(cmd_modes::ModesArgs),
    /// Convert a physical probe description (SI units) into the dimensionless α's and Ω
    Units(cmd_modes::UnitsArgs),
    /// The cantilever library: nominal k, f0, Q and tip radius of common cantilevers
    Cantilevers(cmd_modes::CantileversArgs),
    /// Integrate one trajectory and write time series, switchings, Poincaré points and plots
    Simulate(cmd_simulate::SimulateArgs),
    /// Steady-state tip motion for N = 1..N_max modes (paper Fig. 4)
    Converge(cmd_simulate::ConvergeArgs),
    /// Bifurcation diagram over Ω or any α (paper Fig. 5); the main job
    Bifurcation(cmd_analysis::BifurcationArgs),
    /// Coexisting attractors and basin fractions at fixed parameters (paper Figs. 6–17)
    Attractors(cmd_analysis::AttractorsArgs),
    /// Behaviour chart over two parameters: period, λ₁, X_max and basin fractions per cell
    Chart(cmd_chart::ChartArgs),
    /// Basins of attraction over two coordinates of the initial state; basin entropy
    Basins(cmd_basins::BasinsArgs),
    /// Find a period-n orbit by Newton shooting; Floquet multipliers and stability
    Orbit(cmd_orbits::OrbitArgs),
    /// Pseudo-arclength continuation of a period-n branch; folds, period doublings, grazing
    Continue(cmd_orbits::ContinueArgs),
    /// Lyapunov spectrum (with saltation matrices) and the 0–1 test for chaos
    Lyapunov(cmd_orbits::LyapunovArgs),
    /// Approach–retract curve over the rest distance z_c: stepped both ways, branches, folds
    Approach(cmd_approach::ApproachArgs),
    /// Bimodal (multifrequency) AM approach curve: per drive component A_i, φ_i, virial_i, E_dis,i
    Bimodal(cmd_approach::BimodalArgs),
    /// Resonance curve near a mode: up- and down-sweep in frequency, branches, folds
    Resonance(cmd_approach::ResonanceArgs),
    /// FM-AFM at constant amplitude: frequency shift and excitation over z_c (ideal PLL)
    Fm(cmd_fm::FmArgs),
    /// Off-resonance (PeakForce) tapping: the steady tap's channels, cycle and force curve
    Peakforce(cmd_peakforce::PeakForceArgs),
    /// Fit a measured force curve (Hertz, DMT, JKR): estimates, intervals, correlations, warnings
    Fit(cmd_fit::FitArgs),
    /// Tip–sample force and potential from an FM-AFM frequency-shift curve (Sader–Jarvis)
    Reconstruct(cmd_reconstruct::ReconstructArgs),
    /// AM-AFM image of a heterogeneous sample (ideal or PI feedback): height, phase, E_dis maps
    Image(cmd_image::ImageArgs),
}

fn run(cli: Cli) -> Result<(), CliError> {
    output::set_display_units(cli.units);
    match cli.command {
        Command::Modes(a) => cmd_modes::modes(&a),
        Command::Units(a) => cmd_modes::units(&a),
        Command::Cantilevers(a) => cmd_modes::cantilevers(&a),
        Command::Simulate(a) => cmd_simulate::simulate(&a),
        Command::Converge(a) => cmd_simulate::converge(&a),
        Command::Bifurcation(a) => cmd_analysis::bifurcation(&a),
        Command::Attractors(a) => cmd_analysis::attractors(&a),
        Command::Chart(a) => cmd_chart::chart(&a),
        Command::Basins(a) => cmd_basins::basins_cmd(&a),
        Command::Orbit(a) => cmd_orbits::orbit(&a),
        Command::Continue(a) => cmd_orbits::continuation(&a),
        Command::Lyapunov(a) => cmd_orbits::lyapunov(&a),
        Command::Approach(a) => cmd_approach::approach(&a),
        Command::Bimodal(a) => cmd_approach::bimodal(&a),
        Command::Resonance(a) => cmd_approach::resonance(&a),
        Command::Fm(a) => cmd_fm::fm(&a),
        Command::Peakforce(a) => cmd_peakforce::peakforce(&a),
        Command::Fit(a) => cmd_fit::fit(&a),
        Command::Reconstruct(a) => cmd_reconstruct::reconstruct(&a),
        Command::Image(a) => cmd_image::image_cmd(&a),
    }
}

/// A clap error as one line: its first line plus its "tip:" hints (e.g. a similar argument).
fn one_line(text: &str) -> String {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let mut out = lines
        .next()
        .unwrap_or("invalid arguments")
        .trim_start_matches("error: ")
        .to_string();
    // "the following required arguments were not provided:" lists them on the next lines
    if out.ends_with(':') {
        let mut rest = lines.clone();
        while let Some(l) = rest
            .next()
            .filter(|l| l.starts_with('-') || l.starts_with('<'))
        {
            out.push_str(&format!(" {l}"));
            lines = rest.clone();
        }
    }
    for tip in lines.filter_map(|l| l.strip_prefix("tip: ")) {
        out.push_str(&format!(" ({tip})"));
    }
    out
}

/// The help of every model flag from the library's one table of model parameters
/// ([`afmdyn::request::MODEL_PARAMETERS`]): what it is, its range and its default.
fn with_table_help(mut cmd: clap::Command) -> clap::Command {
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    for name in names {
        cmd = cmd.mut_subcommand(name, |mut sub| {
            for p in &afmdyn::request::MODEL_PARAMETERS {
                // the flag's id is the paper's name where it has one (alpha1 …), else the name
                let id = p.alias.unwrap_or(p.name);
                if sub.get_arguments().any(|a| a.get_id() == id) {
                    let default = if sub.get_name() == "converge" && p.name == "omega" {
                        afmdyn::request::analyses::converge_defaults()
                            .omega
                            .to_string()
                    } else {
                        p.default.to_string()
                    };
                    let mut help = format!("{}; {} [default: {default}]", p.help, p.range);
                    help[..1].make_ascii_uppercase();
                    sub = sub.mut_arg(id, |a| a.help(help));
                }
            }
            sub
        });
    }
    cmd
}

/// The arguments with every negative number joined to the flag before it (`--gap -5e-1` →
/// `--gap=-5e-1`): clap's lexer takes `-5e-1` (a negative exponent) for a cluster of short
/// flags. afmdyn has no positional arguments, so a number after a flag is always its value.
fn joined_negative_numbers(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    for arg in args {
        let number = arg
            .to_str()
            .is_some_and(|a| a.starts_with('-') && a.parse::<f64>().is_ok());
        match out.last_mut() {
            Some(flag)
                if number
                    && flag.to_str().is_some_and(|f| {
                        f.starts_with("--") && f.len() > 2 && !f.contains('=')
                    }) =>
            {
                flag.push("=");
                flag.push(&arg);
            }
            _ => out.push(arg),
        }
    }
    out
}

/// Parse the command line ([`Cli`] with [`with_table_help`]).
fn parse() -> Result<Cli, clap::Error> {
    let matches = with_table_help(Cli::command())
        .try_get_matches_from(joined_negative_numbers(std::env::args_os()))?;
    Cli::from_arg_matches(&matches)
}

/// A reader that closes the pipe (`afmdyn … | head`) ends the run quietly with status 141, as
/// SIGPIPE ends other Unix tools (Rust ignores SIGPIPE, and `println!` panics on the closed
/// pipe instead); every other panic keeps the default report.
fn quiet_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let msg = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}

fn main() {
    quiet_broken_pipe();
    let cli = match parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                std::process::exit(
                    if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                        2
                    } else {
                        0
                    },
                );
            }
            // a failed write of the message itself cannot be reported: the code still says it
            let _ = writeln!(std::io::stderr(), "afmdyn: {}", one_line(&e.to_string()));
            std::process::exit(2);
        }
    };
    if let Err(e) = run(cli) {
        let _ = writeln!(
            std::io::stderr(),
            "afmdyn: {}",
            e.to_string().replace('\n', " ")
        );
        std::process::exit(e.code());
    }
}
