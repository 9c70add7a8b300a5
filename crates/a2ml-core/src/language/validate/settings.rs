//! The settings block, and solver names wherever they are written.

use std::collections::BTreeSet;

use super::Checker;
use super::values::Dimension;
use crate::language::ast::{self, Name};
use crate::language::task::*;
use crate::names::did_you_mean;

const SETTINGS: [&str; 6] = ["rate", "solver", "seed", "transition", "frame", "acceleration"];

impl Checker<'_> {
    pub(super) fn settings(&mut self, settings: &ast::Settings) -> Settings {
        let mut out = Settings::default();
        let mut seen: BTreeSet<&str> = BTreeSet::new();
        for s in &settings.entries {
            if !seen.insert(&s.name.text) && SETTINGS.contains(&s.name.text.as_str()) {
                self.error(s.name.span, format!("setting `{}` is given twice", s.name.text));
                continue;
            }
            match (s.name.text.as_str(), &s.value) {
                ("rate", ast::SettingValue::Quantity(q)) => {
                    if let Some(v) = self.positive(q, Dimension::Frequency, "the rate") {
                        out.rate = v;
                        self.rate_span = q.span;
                    }
                }
                ("solver", ast::SettingValue::Word(w)) => {
                    if let Some(v) = self.solver(w) {
                        out.solver = v;
                    }
                }
                ("seed", ast::SettingValue::Quantity(q)) => {
                    // Read from the text: a number above 2^53 is not exact as a float.
                    let written = self.source.get(q.span.start..q.span.end).unwrap_or("");
                    let exact_float = q.value >= 0.0 && q.value.fract() == 0.0 && q.value < 9.0e15;
                    match (q.unit.is_some(), written.parse::<u64>()) {
                        (false, Ok(seed)) => out.seed = seed,
                        // `7.0` or `1e3`: whole, and exact as a float.
                        (false, Err(_)) if exact_float => out.seed = q.value as u64,
                        _ => self.error(
                            q.span,
                            format!("the seed is a whole number from 0 to {}", u64::MAX),
                        ),
                    }
                }
                ("transition", ast::SettingValue::Quantity(q)) => {
                    if let Some(v) = self.quantity(q, Dimension::Fraction) {
                        if (0.0..1.0).contains(&v) {
                            out.transition = v;
                        } else {
                            let help = (q.unit.is_none() && q.value < 100.0).then(|| {
                                format!("a bare number is a fraction: write `{} %`", q.value)
                            });
                            self.error_with_help(
                                q.span,
                                "the transition overlap is between 0 and 100 %",
                                help,
                            );
                        }
                    }
                }
                ("acceleration", ast::SettingValue::Quantity(q)) => {
                    if let Some(v) = self.quantity(q, Dimension::Fraction) {
                        if v > 0.0 && v <= 10.0 {
                            out.acceleration = v;
                        } else {
                            self.error(
                                q.span,
                                "the acceleration scale is above 0 and at most 1000 %",
                            );
                        }
                    }
                }
                ("frame", ast::SettingValue::Word(w)) => match w.text.as_str() {
                    "base" => out.frame = PositionFrame::Base,
                    "root" => out.frame = PositionFrame::Root,
                    _ => self
                        .error(w.span, format!("the frame is `base` or `root`, not `{}`", w.text)),
                },
                (
                    name @ ("rate" | "solver" | "seed" | "transition" | "frame" | "acceleration"),
                    value,
                ) => {
                    let span = match value {
                        ast::SettingValue::Quantity(q) => q.span,
                        ast::SettingValue::Word(w) => w.span,
                    };
                    let expected = match name {
                        "rate" => "a rate like 100 Hz",
                        "solver" => "a solver name like qp",
                        "seed" => "a whole number",
                        "transition" | "acceleration" => "a percentage like 20 %",
                        _ => "`base` or `root`",
                    };
                    self.error(span, format!("`{name}` takes {expected}"));
                }
                (other, _) => {
                    let help =
                        did_you_mean(other, SETTINGS).map(|s| format!("did you mean `{s}`?"));
                    self.error_with_help(
                        s.name.span,
                        format!(
                            "unknown setting `{other}` (rate, solver, seed, transition, frame, \
                             acceleration)"
                        ),
                        help,
                    );
                }
            }
        }
        out
    }

    pub(super) fn solver(&mut self, name: &Name) -> Option<SolverChoice> {
        let found = SolverChoice::NAMES.iter().find(|(n, _)| *n == name.text).map(|(_, s)| *s);
        if found.is_none() {
            let help = did_you_mean(&name.text, SolverChoice::NAMES.iter().map(|(n, _)| *n))
                .map(|s| format!("did you mean `{s}`?"));
            self.error_with_help(
                name.span,
                format!(
                    "unknown solver `{}` (auto, qp, rrt, map, gpm, clik, pmp, hamp)",
                    name.text
                ),
                help,
            );
        }
        found
    }
}
