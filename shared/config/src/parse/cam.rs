//! `[cams.<name>]`: cams built and interpolated at load time (`MC_InterpolateCam`).

use super::{Ctx, FieldError};
use crate::cell::CamEntry;
use crate::error::{ConfigError, Problem, SegmentProblem};
use crate::schema::{CamSection, CamSegmentSection, CellFile};
use std::path::Path;
use tandem_motion::cam::{
    BoundaryCondition, Cam, CamDefinition, Interpolation, MotionLaw, SegmentDef,
};

/// Every cam of the cell, interpolated; CSV point files are read relative to `dir`.
pub(super) fn cams(
    cx: Ctx<'_>,
    raw: &CellFile,
    dir: Option<&Path>,
) -> Result<Vec<CamEntry>, ConfigError> {
    let mut cams = Vec::new();
    for (name, c) in &raw.cams {
        let (cam, definition) = cam_from(c, dir).map_err(|(key, problem)| {
            let mut path = vec!["cams", name.as_str()];
            if !key.is_empty() {
                path.push(key);
            }
            cx.at_or_table(&path, problem)
        })?;
        cams.push(CamEntry {
            name: name.clone(),
            cam: std::sync::Arc::new(cam),
            definition,
        });
    }
    Ok(cams)
}

/// Builds and interpolates a cam (`MC_InterpolateCam` at load time).
fn cam_from(c: &CamSection, dir: Option<&Path>) -> Result<(Cam, CamDefinition), FieldError> {
    let not_one_of = |key, value: &str, options: &[&'static str]| {
        (
            key,
            Problem::NotOneOf {
                value: value.into(),
                options: options.to_vec(),
            },
        )
    };
    let interpolation = Interpolation::from_name(&c.interpolation).ok_or_else(|| {
        not_one_of(
            "interpolation",
            &c.interpolation,
            &["linear", "cubic_spline", "bezier"],
        )
    })?;
    let boundary = BoundaryCondition::from_name(&c.boundary)
        .ok_or_else(|| not_one_of("boundary", &c.boundary, &["none", "equal_first_derivative"]))?;
    let points = points(c, dir)?;
    let segments = c
        .segments
        .iter()
        .enumerate()
        .map(|(index, seg)| {
            segment(seg).map_err(|problem| ("segments", Problem::Segment { index, problem }))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let def = CamDefinition {
        points,
        segments,
        interpolation,
        boundary,
    };
    let cam = Cam::interpolate(&def).map_err(|e| ("", Problem::Interpolation(e)))?;
    Ok((cam, def))
}

/// The cam's points: `points`, then those of `points_csv`.
fn points(c: &CamSection, dir: Option<&Path>) -> Result<Vec<(f64, f64)>, FieldError> {
    let mut points: Vec<(f64, f64)> = c.points.iter().map(|[x, y]| (*x, *y)).collect();
    if let Some(csv) = &c.points_csv {
        let path = dir
            .map(|d| d.join(csv))
            .unwrap_or_else(|| Path::new(csv).to_path_buf());
        let text = crate::read::read_text(&path, crate::read::CAM_FILE_MAX).map_err(|e| {
            (
                "points_csv",
                Problem::CamFile {
                    path: match e.line {
                        Some(l) => format!("{}:{l}", e.file),
                        None => e.file,
                    },
                    error: e.problem.to_string(),
                },
            )
        })?;
        let more = tandem_motion::cam::parse_csv(&text).map_err(|error| {
            (
                "points_csv",
                Problem::CamCsv {
                    path: path.display().to_string(),
                    error,
                },
            )
        })?;
        points.extend(more);
    }
    Ok(points)
}

/// One segment: a motion law, a polynomial or an S7 polynomial with its sine part.
fn segment(seg: &CamSegmentSection) -> Result<SegmentDef, SegmentProblem> {
    let [x0, x1] = seg.x;
    Ok(match seg.kind.as_str() {
        "law" => {
            let name = seg.law.as_deref().ok_or(SegmentProblem::LawRequired)?;
            let law = MotionLaw::from_name(name, seg.parameter)
                .ok_or_else(|| SegmentProblem::UnknownLaw(name.into()))?;
            let [y0, y1] = seg.y.ok_or(SegmentProblem::YRequired)?;
            SegmentDef::Law {
                law,
                x0,
                x1,
                y0,
                y1,
            }
        }
        "polynomial" => {
            let coeffs = seg
                .coeffs
                .as_deref()
                .filter(|c| !c.is_empty() && c.len() <= 8)
                .ok_or(SegmentProblem::CoeffsRequired)?;
            SegmentDef::polynomial(x0, x1, coeffs)
        }
        "s7_polynomial" => {
            let a_in = seg.a.as_deref().unwrap_or(&[]);
            if a_in.len() > 7 {
                return Err(SegmentProblem::TooManyCoefficients);
            }
            let mut a = [0.0; 7];
            a[..a_in.len()].copy_from_slice(a_in);
            let (amp, period, phase) = seg
                .sine
                .as_ref()
                .map(|s| (s.amplitude, s.period, s.phase))
                .unwrap_or((0.0, 1.0, 0.0));
            SegmentDef::S7Polynomial {
                xmin: x0,
                xmax: x1,
                a,
                sine_amplitude: amp,
                sine_period: period,
                sine_phase: phase,
            }
        }
        other => return Err(SegmentProblem::UnknownType(other.into())),
    })
}
