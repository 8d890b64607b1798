//! Reproductions of issue 27 ("every accepted input answers in bounded time, every refusal
//! speaks the user's units"), each now a test: the library's answer to inputs at the edges of
//! what validation accepts.

use afmdyn::analysis::progress::Progress;
use afmdyn::contact::ContactLaw;
use afmdyn::request::ContinuationRequest;
use afmdyn::{Params, SweepParam};

/// A branch continued from the largest Ω the model accepts (1e5) needs ∂Pⁿ/∂Ω at its first
/// point: a central difference there evaluated Ω = 1.000001e5, which the validation refuses,
/// so the run ended with an error about a value the user never gave. One-sided at the edge.
#[test]
fn continuation_from_the_largest_omega_does_not_step_outside_the_range() {
    let base = Params {
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    };
    let request = ContinuationRequest {
        param: SweepParam::Omega,
        from: 1e5,
        to: 0.99e5,
        ..ContinuationRequest::default()
    };
    let branches = request.run(&base, &Progress::new()).unwrap();
    assert!(branches[0].len() > 2, "{} points", branches[0].len());
    assert!(branches[0].iter().all(|b| b.value <= 1e5));
}
