//! What the results of `sc_match` and `sc_pointwise_map` say about their choice among the
//! verified hypotheses (docs/placement.md): the chosen one's and the runner-up's names,
//! costs and turns, what decided, and the other answer. The accessors themselves are in
//! `correspondence.rs` and `pointwise.rs`; their shared work is here.

use std::ffi::{c_char, CStr, CString};

use super::boundary::{Failure, FfiResult};
use crate::maps::hypotheses::{Decision, HypothesisScore, Verdict};

/// The hypothesis chosen (`sc_correspondence_hypothesis`, `sc_pointwise_hypothesis`).
pub const SC_ANSWER_CHOSEN: u32 = 0;
/// The runner-up: the cheapest other definite hypothesis whose map differs from the chosen
/// one, the answer `sc_correspondence_other_answer` and `sc_pointwise_other_answer` give.
pub const SC_ANSWER_RUNNER_UP: u32 = 1;

/// A result's texts, made once with its handle: the accessors return pointers into them,
/// valid as long as the handle.
pub(crate) struct VerdictText {
    /// The verdict's warning ([`Verdict::warning`]).
    warning: Option<CString>,
    /// The chosen and the runner-up hypothesis's names, by `SC_ANSWER_*`.
    names: [Option<CString>; 2],
}

/// `text` as a C string (a NUL inside, which no name has, becomes a space).
fn c_string(text: String) -> Option<CString> {
    CString::new(text.replace('\0', " ")).ok()
}

impl VerdictText {
    pub(crate) fn new(verdict: Option<&Verdict>) -> Self {
        let name = |which| {
            let score = verdict.and_then(|v| hypothesis(v, which))?;
            c_string(score.kind.name())
        };
        VerdictText {
            warning: verdict.and_then(Verdict::warning).and_then(c_string),
            names: [name(SC_ANSWER_CHOSEN), name(SC_ANSWER_RUNNER_UP)],
        }
    }

    /// The pointer a `_warning` accessor returns: the handle's own string, or NULL.
    pub(crate) fn warning(&self) -> *const c_char {
        self.warning
            .as_deref()
            .map_or(std::ptr::null(), CStr::as_ptr)
    }

    /// The pointer a `_hypothesis` accessor returns: the name of hypothesis `which`, or NULL
    /// when there is none (an error for a `which` that is no `SC_ANSWER_*`).
    pub(crate) fn name(&self, which: u32) -> FfiResult<*const c_char> {
        check_which(which)?;
        Ok(self.names[which as usize]
            .as_deref()
            .map_or(std::ptr::null(), CStr::as_ptr))
    }
}

fn check_which(which: u32) -> FfiResult {
    match which {
        SC_ANSWER_CHOSEN | SC_ANSWER_RUNNER_UP => Ok(()),
        _ => Err(Failure::invalid(format!(
            "which must be SC_ANSWER_CHOSEN (0) or SC_ANSWER_RUNNER_UP (1), got {which}"
        ))),
    }
}

/// The chosen hypothesis or the runner-up ([`Verdict::runner_up`]); None when there is no
/// runner-up or `which` is no `SC_ANSWER_*`.
fn hypothesis(verdict: &Verdict, which: u32) -> Option<&HypothesisScore> {
    match which {
        SC_ANSWER_CHOSEN => Some(verdict.chosen()),
        SC_ANSWER_RUNNER_UP => verdict.runner_up().map(|h| &verdict.scores[h]),
        _ => None,
    }
}

/// A number of hypothesis `which` (`value`), NaN when the result has no verdict or no such
/// hypothesis.
pub(crate) fn hypothesis_value(
    verdict: Option<&Verdict>,
    which: u32,
    value: impl FnOnce(&HypothesisScore) -> f64,
) -> FfiResult<f64> {
    check_which(which)?;
    Ok(verdict
        .and_then(|v| hypothesis(v, which))
        .map_or(f64::NAN, value))
}

/// The name of what decided ([`Decision::name`]) as a static C string, NULL without a
/// verdict.
pub(crate) fn decided_by(verdict: Option<&Verdict>) -> *const c_char {
    let Some(verdict) = verdict else {
        return std::ptr::null();
    };
    let name: &'static CStr = match verdict.decided_by {
        Decision::Cost => c"cost",
        Decision::CloseCall => c"close call",
        Decision::Placement => c"placement",
        Decision::Landmarks => c"landmarks",
        Decision::OtherAnswer => c"other answer",
    };
    name.as_ptr()
}

/// Whether the shapes' placement settled the choice.
pub(crate) fn placement_used(verdict: Option<&Verdict>) -> bool {
    verdict.is_some_and(|v| v.decided_by == Decision::Placement)
}

/// The failure of an `_other_answer` call on a result that has none.
pub(crate) fn no_other_answer(verdict: Option<&Verdict>) -> Failure {
    let why = match verdict {
        None => {
            "the answer was not verified, so there is nothing to choose from (options \
             `verify_hypotheses` and `one_to_one` must be true, and the shapes must allow more \
             than one hypothesis)"
        }
        Some(_) => "no other verified hypothesis gives a different map",
    };
    Failure::invalid(format!("no other answer: {why}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decided_by_names_are_the_decisions_names() {
        for decision in [
            Decision::Cost,
            Decision::CloseCall,
            Decision::Placement,
            Decision::Landmarks,
            Decision::OtherAnswer,
        ] {
            let verdict = Verdict {
                chosen: 0,
                scores: Vec::new(),
                confidence: 1.0,
                decided_by: decision,
                distances: Vec::new(),
                ruled_out: Vec::new(),
            };
            let name = unsafe { CStr::from_ptr(decided_by(Some(&verdict))) };
            assert_eq!(name.to_str().unwrap(), decision.name());
            assert_eq!(
                placement_used(Some(&verdict)),
                decision == Decision::Placement
            );
        }
        assert!(decided_by(None).is_null());
        assert!(!placement_used(None));
    }
}
