//! Loading histories: what drives an experiment and what it observes.

use serde::{Deserialize, Serialize};

/// What the drive samples are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Drive {
    /// Rigid-tool displacement in mm, positive into the body.
    DisplacementMm,
    /// Principal stretch of a homogeneous test (dimensionless).
    Stretch,
    /// Tool position along a path in mm (rolling), at a fixed depth.
    PositionMm,
    /// Amount of shear `gamma` of a homogeneous simple-shear test
    /// (dimensionless: plate travel over the specimen height).
    AmountOfShear,
}

/// What a model predicts at each sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Observable {
    /// Reaction force on the tool in N, positive in compression.
    ForceN,
    /// Nominal (first Piola-Kirchhoff) stress in MPa, positive in tension.
    NominalStressMPa,
}

impl Observable {
    /// Column name used in data files and reports.
    pub fn column(self) -> &'static str {
        match self {
            Observable::ForceN => "force_N",
            Observable::NominalStressMPa => "stress_MPa",
        }
    }
}

/// One output of a model: what it is ([`Observable`]: quantity, unit and
/// sign) and the column it goes to in data files and reports.
///
/// Conventions (every model and wrapper keeps them):
///
/// * A model has at least one output ([`crate::ForwardModel::outputs`]). The
///   **first** is the one [`crate::Evaluator::predict_into`] gives, whose
///   observable is [`crate::ForwardModel::observable`]: estimators, studies
///   and the gap diagnosis, which see one output, see that one. For a tool
///   driven into the body it is the force along the drive, positive in
///   compression, so that enrichments acting on the drive (zero offset, tool
///   compliance) act on it.
/// * `name` is unique within a model and ends in the unit: `force_N` (the
///   first output of a one-output model, [`Observable::column`]), `force_x_N`
///   (a force component along the global x axis, positive along +x),
///   `force_y_N`.
/// * Several outputs per sample are laid out samples x outputs, row-major:
///   output `j` at sample `i` is `out[i * outputs + j]`
///   ([`crate::Evaluator::predict_outputs_into`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Output {
    /// Column name, e.g. `force_N`, `force_x_N`.
    pub name: String,
    /// Quantity, unit and sign convention of the values.
    pub observable: Observable,
}

impl Output {
    /// An output named `name` observing `observable`.
    pub fn new(name: impl Into<String>, observable: Observable) -> Self {
        Output {
            name: name.into(),
            observable,
        }
    }
}

impl From<Observable> for Output {
    /// The single output of a one-output model: named by
    /// [`Observable::column`].
    fn from(observable: Observable) -> Self {
        Output::new(observable.column(), observable)
    }
}

impl Drive {
    /// Column name used in data files and reports.
    pub fn column(self) -> &'static str {
        match self {
            Drive::DisplacementMm => "displacement_mm",
            Drive::Stretch => "stretch",
            Drive::PositionMm => "position_mm",
            Drive::AmountOfShear => "amount_of_shear",
        }
    }
}

/// A loading history: drive samples and, when the response is rate
/// dependent, the time of each sample (s, non-decreasing).
///
/// Models treat the history as piecewise linear between samples.
///
/// ```
/// use palpate_core::{Drive, Loading};
///
/// // A ramp to 2 mm in 4 s, then a hold.
/// let ramp = Loading::timed(
///     Drive::DisplacementMm,
///     vec![0.0, 2.0, 4.0, 10.0],
///     vec![0.0, 1.0, 2.0, 2.0],
/// );
/// assert_eq!(ramp.len(), 4);
/// assert!(ramp.validate().is_ok());
/// // A zero offset shifts the drive and keeps the times.
/// let shifted = ramp.with_drive(ramp.drive.iter().map(|d| (d - 0.5f64).max(0.0)).collect());
/// assert_eq!(shifted.drive, [0.0, 0.5, 1.5, 1.5]);
/// assert_eq!(shifted.time, ramp.time);
/// // Time running backwards is an error naming the sample.
/// let bad = Loading::timed(Drive::DisplacementMm, vec![0.0, 2.0, 1.0], vec![0.0, 1.0, 2.0]);
/// assert!(bad.validate().is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Loading {
    pub drive_kind: Drive,
    pub drive: Vec<f64>,
    pub time: Option<Vec<f64>>,
}

impl Loading {
    /// A rate-independent history of drive samples.
    pub fn quasi_static(drive_kind: Drive, drive: Vec<f64>) -> Self {
        Loading {
            drive_kind,
            drive,
            time: None,
        }
    }

    /// A timed history; `time` and `drive` must have the same length.
    pub fn timed(drive_kind: Drive, time: Vec<f64>, drive: Vec<f64>) -> Self {
        Loading {
            drive_kind,
            drive,
            time: Some(time),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.drive.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.drive.is_empty()
    }

    /// Same history with the drive replaced (e.g. shifted by a zero offset).
    pub fn with_drive(&self, drive: Vec<f64>) -> Self {
        Loading {
            drive_kind: self.drive_kind,
            drive,
            time: self.time.clone(),
        }
    }

    /// Checks lengths, finiteness and monotone time; returns a message naming
    /// the first bad sample.
    pub fn validate(&self) -> Result<(), String> {
        if let Some(t) = &self.time {
            if t.len() != self.drive.len() {
                return Err(format!(
                    "time has {} samples but drive has {}",
                    t.len(),
                    self.drive.len()
                ));
            }
            for i in 1..t.len() {
                if t[i].is_nan() || t[i] < t[i - 1] {
                    return Err(format!(
                        "time decreases at sample {i}: {} -> {}",
                        t[i - 1],
                        t[i]
                    ));
                }
            }
        }
        if let Some(i) = self.drive.iter().position(|d| !d.is_finite()) {
            return Err(format!("drive sample {i} is not finite"));
        }
        Ok(())
    }
}
