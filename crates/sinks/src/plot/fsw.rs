//! The flight code's own telemetry in `flexdyn plot` (issue 37): each stream the recording's
//! configuration declares (`[[fsw_streams]]`) and the samples recorded on
//! `flexdyn/<sc>/fsw/<name>`, drawn against the truth.
//!
//! - `attitude.png` gains, under the attitude, each stream's **mode timeline**: the mode index,
//!   the time in each mode shaded and named, and every event marked;
//! - `fsw_<stream>.png`: the mode timeline, the **pointing error against the flight code's own
//!   target** (the truth attitude B against the target R the flight code published, principal
//!   angle), and the **estimation error** (its estimate against the truth, principal angle);
//! - `fsw_<stream>.estimation.png`: the estimation error about each body axis with ±3σ from the
//!   variances the flight code published (only when it published an estimate);
//! - `fsw_<stream>.values.png`: one panel per declared value (bools as 0/1).
//!
//! (A stream name has no `.`, so no two streams' figures share a name.)
//!
//! Angles: for unit quaternions q₁, q₂ (scalar first), the principal angle of the rotation
//! between them is Φ = 2 atan2(√(1 − d²), |d|) with d = q₁·q₂ (Schaub & Junkins, *Analytical
//! Mechanics of Space Systems*, 4th ed., §3.5: β₀ = cos Φ/2 of the relative rotation). The
//! per-axis estimation error is the principal rotation vector Φ ê of [B̂B] = [B̂N]\[BN\]ᵀ, from
//! its MRP σ = tan(Φ/4) ê (§3.7): Φ ê = 4 atan(|σ|) σ/|σ|, B components.

use std::collections::BTreeMap;

use flexdyn_kernel::attitude::{dcm_to_mrp, quat_to_dcm};
use flexdyn_proto::{fsw_flags, FswMsg};
use flexdyn_vehicle::config::{FswStreamDecl, FswValueType};
use nalgebra::{Vector3, Vector4};
use plotters::style::RGBColor;

use super::{Band, Figure, Line, Panel};

/// The recorded samples of one declared stream, in tick order.
#[derive(Clone, Debug)]
pub struct FswSeries {
    /// The stream's declaration.
    pub decl: FswStreamDecl,
    /// Its samples.
    pub samples: Vec<FswMsg>,
}

/// The truth attitude q_BN by tick.
pub type Truth = BTreeMap<u64, Vector4<f64>>;

/// The pale colours of the mode bands, by mode index (cycling).
const MODE_COLORS: [RGBColor; 6] = [
    RGBColor(158, 202, 225),
    RGBColor(253, 208, 162),
    RGBColor(161, 217, 155),
    RGBColor(218, 218, 235),
    RGBColor(252, 187, 161),
    RGBColor(217, 217, 217),
];

/// The event marks' colours, by severity (info, warning, error, critical).
const EVENT_COLORS: [RGBColor; 4] = [
    RGBColor(49, 130, 189),
    RGBColor(230, 85, 13),
    RGBColor(203, 24, 29),
    RGBColor(84, 39, 143),
];

/// \[s\] a sample's time, as every sink writes `t_s`.
fn t_s(m: &FswMsg) -> f64 {
    m.header.sim_time_ns as f64 / 1e9
}

/// `q` scaled to unit length; `None` for a quaternion too short to be an attitude (below
/// 0.5: flight code's single-precision rounding is many orders smaller).
fn unit(q: &Vector4<f64>) -> Option<Vector4<f64>> {
    let n = q.norm();
    (n > 0.5 && n.is_finite()).then(|| q / n)
}

/// The relative rotation's quaternion q₁* ⊗ q₂ (scalar first; its scalar part is q₁·q₂).
fn relative(q1: &Vector4<f64>, q2: &Vector4<f64>) -> Vector4<f64> {
    let (a0, a) = (q1[0], Vector3::new(q1[1], q1[2], q1[3]));
    let (b0, b) = (q2[0], Vector3::new(q2[1], q2[2], q2[3]));
    let v = a0 * b - b0 * a - a.cross(&b);
    Vector4::new(a0 * b0 + a.dot(&b), v[0], v[1], v[2])
}

/// The principal angle between two attitudes given as quaternions (module docs) \[rad\]:
/// Φ = 2 atan2(|q_v|, |q_0|) of their relative rotation, from the quaternions scaled to unit
/// length (accurate for small angles too); `None` for a quaternion that is not an attitude.
pub fn principal_angle_rad(q1: &Vector4<f64>, q2: &Vector4<f64>) -> Option<f64> {
    let r = relative(&unit(q1)?, &unit(q2)?);
    let v = Vector3::new(r[1], r[2], r[3]).norm();
    Some(2.0 * v.atan2(r[0].abs()))
}

/// The estimate's error about each body axis (module docs) \[rad\]; `None` for a quaternion
/// that is not an attitude.
pub fn axis_errors_rad(q_est_bn: &Vector4<f64>, q_bn: &Vector4<f64>) -> Option<Vector3<f64>> {
    let c = quat_to_dcm(&unit(q_est_bn)?) * quat_to_dcm(&unit(q_bn)?).transpose();
    let sigma = dcm_to_mrp(&c);
    let n = sigma.norm();
    Some(if n == 0.0 {
        Vector3::zeros()
    } else {
        sigma * (4.0 * n.atan() / n)
    })
}

/// The mode timeline of a stream: the mode index, a band per mode over the time spent in it,
/// and a band per event name marking when it was raised; `None` if the stream declares no
/// modes and no events.
pub fn mode_panel(series: &FswSeries) -> Option<Panel> {
    let decl = &series.decl;
    if decl.modes.is_empty() && decl.events.is_empty() {
        return None;
    }
    let s = &series.samples;
    let (t0, t1) = match (s.first(), s.last()) {
        (Some(a), Some(b)) => (t_s(a), t_s(b)),
        _ => return None,
    };
    // An event is marked over 0.4 % of the time span (at least one sample wide), so it shows.
    let mark = ((t1 - t0) * 0.004).max(s.get(1).map_or(0.0, |b| t_s(b) - t0));
    let mut mode_spans: Vec<Vec<(f64, f64)>> = vec![Vec::new(); decl.modes.len()];
    let mut event_spans: Vec<Vec<(f64, f64)>> = vec![Vec::new(); decl.events.len()];
    let mut points = Vec::with_capacity(s.len());
    for (i, m) in s.iter().enumerate() {
        let t = t_s(m);
        let next = s.get(i + 1).map_or(t, t_s);
        if m.flags & fsw_flags::MODE != 0 {
            let k = m.mode as usize;
            points.push((t, m.mode as f64));
            if let Some(spans) = mode_spans.get_mut(k) {
                match spans.last_mut() {
                    Some(last) if last.1 == t => last.1 = next,
                    _ => spans.push((t, next)),
                }
            }
        }
        for &e in m.event_indices() {
            if let Some(spans) = event_spans.get_mut(usize::from(e)) {
                spans.push((t, t + mark));
            }
        }
    }
    let mut bands: Vec<Band> = decl
        .modes
        .iter()
        .zip(mode_spans)
        .enumerate()
        .filter(|(_, (_, spans))| !spans.is_empty())
        .map(|(k, (name, spans))| Band {
            label: format!("{k}: {name}"),
            color: MODE_COLORS[k % MODE_COLORS.len()],
            alpha: 0.6,
            spans,
        })
        .collect();
    bands.extend(
        decl.events
            .iter()
            .zip(event_spans)
            .filter(|(_, spans)| !spans.is_empty())
            .map(|(e, spans)| {
                let sev = e.severity as usize;
                Band {
                    label: format!("event {} ({}) ×{}", e.name, e.severity.name(), spans.len()),
                    color: EVENT_COLORS[sev.min(EVENT_COLORS.len() - 1)],
                    alpha: 0.8,
                    spans,
                }
            }),
    );
    let lines = if points.is_empty() {
        // Events only: a flat line spans the axis.
        vec![Line {
            label: "samples".into(),
            points: vec![(t0, 0.0), (t1, 0.0)],
        }]
    } else {
        vec![Line {
            label: "mode".into(),
            points,
        }]
    };
    Some(Panel {
        caption: Some(format!("flight code `{}`: mode and events", decl.name)),
        y_label: "mode (index)".into(),
        lines,
        bands,
        ..Panel::default()
    })
}

/// `fsw_<stream>.png`, `fsw_<stream>.estimation.png`, `fsw_<stream>.values.png` (module docs).
pub fn figures(series: &FswSeries, truth: &Truth) -> Vec<Figure> {
    let name = &series.decl.name;
    let s = &series.samples;
    let mut out = Vec::new();
    let truth_at = |m: &FswMsg| truth.get(&m.header.tick);
    let q = |a: [f64; 4]| Vector4::new(a[0], a[1], a[2], a[3]);
    // The pointing error against the flight code's target, and the estimation error, where
    // the truth of the same tick is recorded.
    let mut pointing = Vec::new();
    let mut estimation = Vec::new();
    let mut axes: [Vec<(f64, f64)>; 3] = Default::default();
    let mut bounds: [Vec<(f64, f64)>; 3] = Default::default();
    for m in s {
        let Some(q_bn) = truth_at(m) else { continue };
        let t = t_s(m);
        if m.flags & fsw_flags::TARGET != 0 {
            if let Some(a) = principal_angle_rad(q_bn, &q(m.q_target_rn)) {
                pointing.push((t, a.to_degrees()));
            }
        }
        if m.flags & fsw_flags::ESTIMATE != 0 {
            let q_est = q(m.q_est_bn);
            let (Some(a), Some(e)) = (
                principal_angle_rad(q_bn, &q_est),
                axis_errors_rad(&q_est, q_bn),
            ) else {
                continue;
            };
            estimation.push((t, a.to_degrees()));
            for i in 0..3 {
                axes[i].push((t, e[i].to_degrees()));
                if m.flags & fsw_flags::COVARIANCE != 0 {
                    bounds[i].push((t, 3.0 * m.att_var_b_rad2[i].max(0.0).sqrt().to_degrees()));
                }
            }
        }
    }
    let mut panels: Vec<Panel> = mode_panel(series).into_iter().collect();
    if !pointing.is_empty() {
        panels.push(Panel {
            y_label: "pointing error (deg)".into(),
            lines: vec![Line {
                label: "truth B vs the flight code's target R".into(),
                points: pointing,
            }],
            ..Panel::default()
        });
    }
    if !estimation.is_empty() {
        panels.push(Panel {
            y_label: "estimation error (deg)".into(),
            lines: vec![Line {
                label: "estimate vs truth (principal angle)".into(),
                points: estimation,
            }],
            ..Panel::default()
        });
    }
    if !panels.is_empty() {
        out.push(Figure {
            name: format!("fsw_{name}.png"),
            title: format!(
                "Flight code `{name}`: modes and events, pointing and estimation against the truth"
            ),
            panels,
            columns: 1,
        });
    }
    if !axes[0].is_empty() {
        let panels = (0..3)
            .map(|i| {
                let mut lines = vec![Line {
                    label: format!("δθ{} (estimate vs truth)", i + 1),
                    points: std::mem::take(&mut axes[i]),
                }];
                if !bounds[i].is_empty() {
                    let minus = bounds[i].iter().map(|&(t, b)| (t, -b)).collect();
                    lines.push(Line {
                        label: "+3σ".into(),
                        points: std::mem::take(&mut bounds[i]),
                    });
                    lines.push(Line {
                        label: "−3σ".into(),
                        points: minus,
                    });
                }
                Panel {
                    y_label: format!("about b{} (deg)", i + 1),
                    lines,
                    ..Panel::default()
                }
            })
            .collect();
        out.push(Figure {
            name: format!("fsw_{name}.estimation.png"),
            title: format!(
                "Flight code `{name}`: attitude estimation error about each body axis, with its 3σ"
            ),
            panels,
            columns: 1,
        });
    }
    let values: Vec<Panel> = series
        .decl
        .values
        .iter()
        .map(|v| {
            let lines = (0..v.len)
                .map(|k| Line {
                    label: v.element_name(k),
                    points: s
                        .iter()
                        .filter_map(|m| {
                            let w = *m.values.get(v.offset + k)?;
                            Some((t_s(m), flexdyn_vehicle::config::word_as_f64(v.ty, w)))
                        })
                        .filter(|(_, y)| y.is_finite())
                        .collect(),
                })
                .collect();
            let unit = match (v.ty, v.unit.as_str()) {
                (FswValueType::Bool, _) => "0/1".to_owned(),
                (_, "") => "–".to_owned(),
                (_, u) => u.to_owned(),
            };
            Panel {
                y_label: format!("{} ({unit})", v.name),
                lines,
                ..Panel::default()
            }
        })
        .collect();
    if !values.is_empty() {
        let columns = if values.len() > 4 { 2 } else { 1 };
        out.push(Figure {
            name: format!("fsw_{name}.values.png"),
            title: format!("Flight code `{name}`: its declared values"),
            panels: values,
            columns,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q_about_z(angle_rad: f64) -> Vector4<f64> {
        Vector4::new((angle_rad / 2.0).cos(), 0.0, 0.0, (angle_rad / 2.0).sin())
    }

    /// Closed forms: two rotations about one axis differ by the difference of their angles,
    /// whatever the quaternions' signs; the per-axis error of a rotation about b3 is on b3.
    #[test]
    fn angles_are_the_closed_forms() {
        let a = q_about_z(0.3);
        let b = q_about_z(0.3 + 1e-3);
        let angle = |x: &Vector4<f64>, y: &Vector4<f64>| principal_angle_rad(x, y).unwrap();
        assert!((angle(&a, &b) - 1e-3).abs() < 1e-12);
        assert!((angle(&a, &(-b)) - 1e-3).abs() < 1e-12);
        assert!((angle(&a, &q_about_z(0.3 + 2.0)) - 2.0).abs() < 1e-12);
        // Small angles stay accurate, and a quaternion off unit length (single precision) is
        // scaled, not read as an error: 1e-7 rad between two quaternions 1e-7 too long.
        let c = q_about_z(0.3 + 1e-7) * (1.0 + 1e-7);
        assert!((angle(&(a * (1.0 + 1e-7)), &c) - 1e-7).abs() < 1e-15);
        assert!(principal_angle_rad(&a, &Vector4::zeros()).is_none());
        let e = axis_errors_rad(&b, &a).unwrap();
        assert!(e[0].abs() < 1e-15 && e[1].abs() < 1e-15, "{e:?}");
        assert!((e[2].abs() - 1e-3).abs() < 1e-12, "{e:?}");
    }
}
