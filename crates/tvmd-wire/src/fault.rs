//! The controller's fault detection as words: its settings in the configuration
//! ([`put_fault_detection`]) and, after each cycle, what the detector reported and the mask
//! in force ([`put_fault_answer`]), so that an f32 target flies and reports the detector as
//! the host does.

use tvmd_core::{
    FailureMask, FaultDetection, FaultKind, FaultMasking, FaultReport, FaultResponse, FaultSource,
    FaultVerdict,
};

use crate::{get_hover, mask_bits, mask_of, put_hover, Reader, Writer, AGENTS, HOVER_WORDS};

/// Words of [`put_fault_detection`]: flag, `epsilon`, `k`, persistence, response.
pub const FAULT_DETECTION_WORDS: usize = 5;

/// Words of [`put_fault_answer`]: the report (flag, verdict 5 with the source in the kind
/// word's second byte, statistic, threshold, the two misfits), the masking (flag, agent, hover flag, [`HOVER_WORDS`]) and the mask in force.
pub const FAULT_ANSWER_WORDS: usize = 1 + 5 + 4 + 3 + HOVER_WORDS + 1;

/// Appends the fault detection settings (all zero when off).
pub fn put_fault_detection(w: &mut Writer<'_>, d: Option<&FaultDetection<f32>>) -> Option<()> {
    match d {
        None => w.f32s(&[0.0; FAULT_DETECTION_WORDS]),
        Some(d) => {
            w.u32(1)?;
            w.f32s(&[d.model_error(), d.threshold()])?;
            w.u32(d.persistence())?;
            w.u32(match d.response() {
                FaultResponse::Report => 0,
                FaultResponse::Mask => 1,
            })
        }
    }
}

/// Reads the settings written by [`put_fault_detection`]: `None` for malformed words (an
/// unknown flag or response, values [`FaultDetection::new`] refuses).
pub fn get_fault_detection(r: &mut Reader<'_>) -> Option<Option<FaultDetection<f32>>> {
    let flag = r.u32()?;
    let [model_error, threshold] = r.array()?;
    let persistence = r.u32()?;
    let response = match r.u32()? {
        0 => FaultResponse::Report,
        1 => FaultResponse::Mask,
        _ => return None,
    };
    match flag {
        0 => Some(None),
        1 => FaultDetection::new(model_error, threshold, persistence, response)
            .ok()
            .map(Some),
        _ => None,
    }
}

/// What the detector said after a cycle, as a host reads it from a target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultAnswer {
    /// `Controller::fault_report`.
    pub report: Option<FaultReport<f32>>,
    /// `Controller::fault_masking`.
    pub masking: Option<FaultMasking<f32>>,
    /// `Controller::failures`: the mask in force (the detector may have set it).
    pub failures: FailureMask<AGENTS>,
}

/// Appends a cycle's [`FaultAnswer`] ([`FAULT_ANSWER_WORDS`] words).
pub fn put_fault_answer(w: &mut Writer<'_>, answer: &FaultAnswer) -> Option<()> {
    match &answer.report {
        None => w.f32s(&[0.0; 10])?,
        Some(report) => {
            w.u32(1)?;
            put_verdict(w, &report.verdict, report.source)?;
            w.f32s(&[
                report.statistic,
                report.threshold,
                report.best_misfit,
                report.runner_up_misfit,
            ])?;
        }
    }
    match &answer.masking {
        None => w.f32s(&[0.0; 3 + HOVER_WORDS])?,
        Some(m) => {
            w.u32(1)?;
            w.u32(u32::try_from(m.agent).ok()?)?;
            match &m.hover {
                None => w.f32s(&[0.0; 1 + HOVER_WORDS])?,
                Some(h) => {
                    w.u32(1)?;
                    put_hover(w, h)?;
                }
            }
        }
    }
    w.u32(mask_bits(&answer.failures))
}

/// Reads a [`FaultAnswer`] written by [`put_fault_answer`].
pub fn get_fault_answer(r: &mut Reader<'_>) -> Option<FaultAnswer> {
    let report = match r.u32()? {
        0 => {
            r.array::<9>()?;
            None
        }
        _ => {
            let (verdict, source) = get_verdict(r)?;
            let [statistic, threshold, best_misfit, runner_up_misfit] = r.array()?;
            Some(FaultReport {
                verdict,
                source,
                statistic,
                threshold,
                best_misfit,
                runner_up_misfit,
            })
        }
    };
    let masked = r.u32()?;
    let agent = r.u32()? as usize;
    let hovered = r.u32()?;
    let hover = if hovered == 0 {
        r.array::<HOVER_WORDS>()?;
        None
    } else {
        Some(get_hover(r)?)
    };
    let masking = (masked != 0).then_some(FaultMasking { agent, hover });
    Some(FaultAnswer {
        report,
        masking,
        failures: mask_of(r.u32()?),
    })
}

/// Verdict tag, agent, kind tag (the source, 0 residual or 1 reports, in its second byte),
/// efficiency, periods.
fn put_verdict(w: &mut Writer<'_>, v: &FaultVerdict<f32>, source: FaultSource) -> Option<()> {
    let (tag, agent, kind, periods) = match *v {
        FaultVerdict::Nominal => (0, 0, None, 0),
        FaultVerdict::Unexplained => (1, 0, None, 0),
        FaultVerdict::Suspected {
            agent,
            kind,
            periods,
        } => (2, agent, Some(kind), periods),
        FaultVerdict::Confirmed { agent, kind } => (3, agent, Some(kind), 0),
    };
    w.u32(tag)?;
    w.u32(u32::try_from(agent).ok()?)?;
    let (kind, efficiency) = match kind {
        None | Some(FaultKind::Loss) => (0, 0.0),
        Some(FaultKind::PartialLoss { efficiency }) => (1, efficiency),
        Some(FaultKind::StuckGimbal) => (2, 0.0),
        Some(FaultKind::LinkLoss) => (3, 0.0),
    };
    let source = match source {
        FaultSource::Residual => 0,
        FaultSource::Reports => 1 << 8,
    };
    w.u32(kind | source)?;
    w.f32(efficiency)?;
    w.u32(periods)
}

fn get_verdict(r: &mut Reader<'_>) -> Option<(FaultVerdict<f32>, FaultSource)> {
    let tag = r.u32()?;
    let agent = r.u32()? as usize;
    let word = r.u32()?;
    let source = match word >> 8 {
        0 => FaultSource::Residual,
        1 => FaultSource::Reports,
        _ => return None,
    };
    let kind = match (word & 0xff, r.f32()?) {
        (0, _) => FaultKind::Loss,
        (1, efficiency) => FaultKind::PartialLoss { efficiency },
        (2, _) => FaultKind::StuckGimbal,
        (3, _) => FaultKind::LinkLoss,
        _ => return None,
    };
    let periods = r.u32()?;
    let verdict = match tag {
        0 => FaultVerdict::Nominal,
        1 => FaultVerdict::Unexplained,
        2 => FaultVerdict::Suspected {
            agent,
            kind,
            periods,
        },
        3 => FaultVerdict::Confirmed { agent, kind },
        _ => return None,
    };
    Some((verdict, source))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use tvmd_core::{HoverCapability, HoverLimit};

    #[test]
    fn settings_and_answers_round_trip() {
        let d = FaultDetection::new(0.02f32, 4.5, 3, FaultResponse::Mask).unwrap();
        for settings in [None, Some(d)] {
            let mut buf = [0u32; FAULT_DETECTION_WORDS];
            let mut w = Writer::new(&mut buf);
            put_fault_detection(&mut w, settings.as_ref()).unwrap();
            assert_eq!(w.len(), FAULT_DETECTION_WORDS);
            assert_eq!(get_fault_detection(&mut Reader::new(&buf)), Some(settings));
        }
        let mut failures = FailureMask::none();
        failures.set(2, true).unwrap();
        let hover = HoverCapability {
            capable: true,
            margin: 0.25,
            limiting_agent: Some(1),
            limit: HoverLimit::GimbalY,
            weight: 40.0,
        };
        let report = |verdict| FaultReport {
            verdict,
            source: FaultSource::Residual,
            statistic: 7.5,
            threshold: 5.0,
            best_misfit: 0.5,
            runner_up_misfit: 9.0,
        };
        let answers = [
            FaultAnswer {
                report: None,
                masking: None,
                failures: FailureMask::none(),
            },
            FaultAnswer {
                report: Some(report(FaultVerdict::Suspected {
                    agent: 3,
                    kind: FaultKind::PartialLoss { efficiency: 0.5 },
                    periods: 2,
                })),
                masking: None,
                failures,
            },
            FaultAnswer {
                report: Some(report(FaultVerdict::Confirmed {
                    agent: 2,
                    kind: FaultKind::Loss,
                })),
                masking: Some(FaultMasking {
                    agent: 2,
                    hover: Some(hover),
                }),
                failures,
            },
            FaultAnswer {
                report: Some(FaultReport {
                    source: FaultSource::Reports,
                    ..report(FaultVerdict::Confirmed {
                        agent: 1,
                        kind: FaultKind::LinkLoss,
                    })
                }),
                masking: None,
                failures,
            },
            FaultAnswer {
                report: Some(report(FaultVerdict::Unexplained)),
                masking: Some(FaultMasking {
                    agent: 1,
                    hover: None,
                }),
                failures,
            },
        ];
        for answer in answers {
            let mut buf = [0u32; FAULT_ANSWER_WORDS];
            let mut w = Writer::new(&mut buf);
            put_fault_answer(&mut w, &answer).unwrap();
            assert_eq!(w.len(), FAULT_ANSWER_WORDS);
            assert_eq!(get_fault_answer(&mut Reader::new(&buf)), Some(answer));
        }
        // An unknown response word is malformed, not a default.
        let mut buf = [0u32; FAULT_DETECTION_WORDS];
        put_fault_detection(&mut Writer::new(&mut buf), Some(&d)).unwrap();
        buf[4] = 7;
        assert_eq!(get_fault_detection(&mut Reader::new(&buf)), None);
    }
}
