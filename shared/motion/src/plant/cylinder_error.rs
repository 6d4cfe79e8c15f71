//! The error of a simulated cylinder's parameters, a leaf both `plant::hydraulic` (which
//! checks them) and `plant::analog` (whose connection refuses a device with one) name.

use crate::catalog::hyd_error::HydErrorCode;

/// A parameter of the simulated cylinder out of its range.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CylinderError {
    /// The parameter's name (a field of `CylinderParams` of the simulated valve and cylinder).
    pub name: &'static str,
    /// Its value.
    pub value: f64,
}

impl CylinderError {
    /// The library's error code: `dwTcHydErrIllegalAreas` for the areas, else
    /// `dwTcHydAdsErrIllegalValue`.
    pub fn code(&self) -> HydErrorCode {
        match self.name {
            "area_a" | "area_b" => HydErrorCode::ILLEGAL_AREAS,
            _ => HydErrorCode::ILLEGAL_VALUE,
        }
    }
}

impl core::fmt::Display for CylinderError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "cylinder parameter `{}` = {} is out of its range",
            self.name, self.value
        )
    }
}

impl std::error::Error for CylinderError {}
