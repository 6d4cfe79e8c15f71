//! Cam points from CSV text (see [`parse_csv`]).

use core::fmt;

/// What is wrong with a CSV line.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum CamParseErrorKind {
    /// Not exactly two comma-separated fields.
    FieldCount {
        /// Fields found.
        found: usize,
    },
    /// Field `column` (0 = x, 1 = y) is not a number.
    InvalidNumber {
        /// 0 for x, 1 for y.
        column: usize,
    },
    /// Field `column` is NaN or infinite.
    NonFinite {
        /// 0 for x, 1 for y.
        column: usize,
    },
}

/// A CSV error with its 1-based line number.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct CamParseError {
    /// Line number, starting at 1.
    pub line: usize,
    /// What is wrong.
    pub kind: CamParseErrorKind,
}

impl fmt::Display for CamParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let col = |c: usize| if c == 0 { "x" } else { "y" };
        match self.kind {
            CamParseErrorKind::FieldCount { found } => write!(
                f,
                "line {}: expected 2 fields `x,y`, found {found}",
                self.line
            ),
            CamParseErrorKind::InvalidNumber { column } => {
                write!(f, "line {}: {} is not a number", self.line, col(column))
            }
            CamParseErrorKind::NonFinite { column } => {
                write!(f, "line {}: {} is not finite", self.line, col(column))
            }
        }
    }
}

impl std::error::Error for CamParseError {}

/// Parses CSV cam points. Pure; an empty text gives an empty list.
///
/// Format: one point `x,y` per line (a comma between exactly two numbers; spaces around the
/// fields are ignored). `#` starts a comment that runs to the end of the line; blank lines are
/// skipped; `\r\n` line ends are accepted. The first non-blank line may be a header: it is
/// skipped when **none** of its fields is a number (`x,y`, `leading,following`). Numbers are
/// Rust `f64` syntax (`1`, `-2.5`, `1e-3`); non-finite values are errors. Point order is kept
/// (for [`super::CamDefinition::points`], where the last of equal x wins).
pub fn parse_csv(text: &str) -> Result<Vec<(f64, f64)>, CamParseError> {
    let mut points = Vec::new();
    let mut first = true;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let fields: Vec<&str> = content.split(',').map(str::trim).collect();
        let is_first = first;
        first = false;
        if is_first && fields.iter().all(|f| f.parse::<f64>().is_err()) {
            continue;
        }
        if fields.len() != 2 {
            return Err(CamParseError {
                line,
                kind: CamParseErrorKind::FieldCount {
                    found: fields.len(),
                },
            });
        }
        let mut v = [0.0; 2];
        for (column, field) in fields.iter().enumerate() {
            let x: f64 = field.parse().map_err(|_| CamParseError {
                line,
                kind: CamParseErrorKind::InvalidNumber { column },
            })?;
            if !x.is_finite() {
                return Err(CamParseError {
                    line,
                    kind: CamParseErrorKind::NonFinite { column },
                });
            }
            v[column] = x;
        }
        points.push((v[0], v[1]));
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_points_with_header_comments_and_blank_lines() {
        let text = "# lift cam\nx, y\n0,0\n\n 90 , 10.5 # top\r\n180,-1e1\n";
        assert_eq!(
            parse_csv(text).unwrap(),
            vec![(0.0, 0.0), (90.0, 10.5), (180.0, -10.0)]
        );
        assert_eq!(parse_csv("").unwrap(), vec![]);
        assert_eq!(parse_csv("# only\n\n").unwrap(), vec![]);
        assert_eq!(parse_csv("0,1\n").unwrap(), vec![(0.0, 1.0)]);
    }

    #[test]
    fn reports_line_numbers() {
        let e = parse_csv("x,y\n0,0\n1,2,3\n").unwrap_err();
        assert_eq!(e.line, 3);
        assert_eq!(e.kind, CamParseErrorKind::FieldCount { found: 3 });
        let e = parse_csv("0,0\n# c\n1,abc\n").unwrap_err();
        assert_eq!(e.line, 3);
        assert_eq!(e.kind, CamParseErrorKind::InvalidNumber { column: 1 });
        let e = parse_csv("0,0\n1,2\nx,y\n").unwrap_err();
        assert_eq!(e.line, 3, "a header only on the first line");
        let e = parse_csv("0,1x\n").unwrap_err();
        assert_eq!(e.kind, CamParseErrorKind::InvalidNumber { column: 1 });
        let e = parse_csv("0,0\ninf,1\n").unwrap_err();
        assert_eq!(
            (e.line, e.kind),
            (2, CamParseErrorKind::NonFinite { column: 0 })
        );
        let e = parse_csv("0;1\n2;3\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert_eq!(e.to_string(), "line 2: expected 2 fields `x,y`, found 1");
    }
}
