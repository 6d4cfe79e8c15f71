//! `[encoders.<name>]`: external encoders, their simulated sources and extrapolation.

use super::axis::{extrapolation, ENCODER_TYPES};
use super::{node_named, pick, Ctx};
use crate::cell::{AxisEntry, AxisIndex, EncoderEntry, EncoderSource, LeadingValueConfig, Node};
use crate::error::{ConfigError, Problem};
use crate::schema::{CellFile, EncoderSection};
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::encoder::EncoderConfig;

/// Every external encoder (after the axes: a source may name one). Leading values follow.
pub(super) fn encoders(
    cx: Ctx<'_>,
    raw: &CellFile,
    axes: &[AxisEntry],
    nodes: &[Node],
) -> Result<Vec<EncoderEntry>, ConfigError> {
    let mut encoders = Vec::new();
    for (name, e) in &raw.encoders {
        if raw.axes.contains_key(name) {
            return Err(cx.at(&["encoders", name], Problem::AlsoAnAxis(name.clone())));
        }
        let node = node_named(cx, nodes, &e.node, &["encoders", name, "node"])?;
        let encoder = pick("encoder", &e.encoder, &ENCODER_TYPES)
            .map_err(|(k, p)| cx.at(&["encoders", name, k], p))?;
        let source = source(e, axes).map_err(|(k, p)| cx.at(&["encoders", name, k], p))?;
        let config = EncoderConfig {
            cycle: nodes[node].cycle_ns as f64 * 1e-9,
            modulo: e.modulo.as_ref().map(|m| Modulo {
                start: m.start,
                length: m.length,
            }),
            encoder,
            extrapolation: extrapolation(&e.extrapolation)
                .map_err(|(k, p)| cx.at(&["encoders", name, k], p))?,
        };
        if let Some(m) = config.modulo {
            if !(m.length.is_finite() && m.length > 0.0 && m.start.is_finite()) {
                return Err(cx.at(
                    &["encoders", name, "modulo"],
                    Problem::Invalid("length must be positive"),
                ));
            }
        }
        encoders.push(EncoderEntry {
            name: name.clone(),
            node,
            config,
            source,
            leading: LeadingValueConfig {
                delay_ns: 0,
                tolerance_ns: 0,
            },
        });
    }
    Ok(encoders)
}

/// The simulated source of encoder `e`: an axis' actual position or a velocity profile.
fn source(e: &EncoderSection, axes: &[AxisEntry]) -> Result<EncoderSource, super::FieldError> {
    match e.source.as_str() {
        "axis" => {
            let axis_name = e.axis.as_deref().ok_or((
                "source",
                Problem::Invalid("source = \"axis\" needs `axis = \"<name>\"`"),
            ))?;
            let axis = axes
                .iter()
                .position(|a| a.name == axis_name)
                .ok_or_else(|| {
                    (
                        "axis",
                        Problem::Unknown {
                            what: "axis",
                            name: axis_name.into(),
                            known: None,
                        },
                    )
                })?;
            if !(e.scale.is_finite() && e.scale != 0.0) {
                return Err(("scale", Problem::Invalid("must be a non-zero number")));
            }
            Ok(EncoderSource::Axis {
                axis: AxisIndex(axis),
                scale: e.scale,
            })
        }
        "profile" => {
            let pts = e.profile.as_ref().ok_or((
                "source",
                Problem::Invalid("source = \"profile\" needs `profile = [[t, v], ...]`"),
            ))?;
            let mut last = 0.0;
            for [t, v] in pts {
                if !(t.is_finite() && v.is_finite() && *t >= last) {
                    return Err((
                        "profile",
                        Problem::Invalid(
                            "points must be finite [time, velocity] pairs with times rising from 0",
                        ),
                    ));
                }
                last = *t;
            }
            Ok(EncoderSource::Profile(
                pts.iter().map(|[t, v]| (*t, *v)).collect(),
            ))
        }
        other => Err((
            "source",
            Problem::NotOneOf {
                value: other.into(),
                options: vec!["axis", "profile"],
            },
        )),
    }
}
