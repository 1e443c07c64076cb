//! AR analysis of a record's columns, as `host-sim arfit` runs it: per
//! column the AR(p) fits by every method ([`super::arfit`]), the
//! autocorrelation and the order-selection scores, and the model file the
//! filter loads.

use super::ar_file::{ArModelEntry, ArModelFile};
use super::arfit::{autocorrelation, fit_ar, order_scores, ArFit, ArMethod, OrderScore};
use super::csv_input::AnalysisInput;
use super::units::InputUnit;
use anyhow::{Context, Result};

/// The fitting methods, in report order.
pub const METHODS: [ArMethod; 3] = [ArMethod::YuleWalker, ArMethod::Burg, ArMethod::Covariance];

/// What to fit and report.
#[derive(Clone, Copy, Debug)]
pub struct ArOptions {
    /// Model order p of the fits.
    pub order: usize,
    /// Method of the order scores and of the model file.
    pub method: ArMethod,
    /// Highest order scored.
    pub max_order: usize,
    /// Autocorrelation lags.
    pub lags: usize,
    /// Remove each series' mean before fitting.
    pub demean: bool,
}

/// One column's analysis.
pub struct ColumnAr {
    pub name: String,
    pub unit: InputUnit,
    /// One fit per [`METHODS`], same order.
    pub fits: Vec<ArFit>,
    /// Autocorrelation at lags 0..=lags.
    pub autocorrelation: Vec<f64>,
    /// Scores of orders 1..=max_order by the options' method.
    pub scores: Vec<OrderScore>,
}

impl ColumnAr {
    /// The order of the lowest AIC (0 without scores).
    pub fn best_aic(&self) -> usize {
        let best = self.scores.iter().min_by(|a, b| a.aic.total_cmp(&b.aic));
        best.map_or(0, |s| s.order)
    }

    /// The order of the lowest BIC (0 without scores).
    pub fn best_bic(&self) -> usize {
        let best = self.scores.iter().min_by(|a, b| a.bic.total_cmp(&b.bic));
        best.map_or(0, |s| s.order)
    }

    /// The fit of `method`.
    pub fn fit(&self, method: ArMethod) -> Option<&ArFit> {
        self.fits.iter().find(|f| f.method == method)
    }
}

/// Analyses every selected column of `input` in SI units.
pub fn analyse_columns(input: &AnalysisInput, options: &ArOptions) -> Result<Vec<ColumnAr>> {
    input
        .si_columns()
        .map(|(name, unit, x)| {
            let fits = METHODS
                .iter()
                .map(|&method| fit_ar(&x, options.order, method, options.demean))
                .collect::<Result<_>>()
                .with_context(|| format!("column {name}"))?;
            let scores = order_scores(&x, options.max_order, options.method, options.demean)
                .with_context(|| format!("column {name}"))?;
            Ok(ColumnAr {
                name: name.to_string(),
                unit,
                fits,
                autocorrelation: autocorrelation(&x, options.lags),
                scores,
            })
        })
        .collect()
}

/// The model file of every column's `method` fit, sampled at `rate_hz`.
pub fn model_file(columns: &[ColumnAr], method: ArMethod, rate_hz: f64) -> ArModelFile {
    let entries = columns
        .iter()
        .filter_map(|c| {
            let fit = c.fit(method)?;
            let quantity = c.unit.quantity().into();
            Some(ArModelEntry::from_fit(&c.name, quantity, rate_hz, fit))
        })
        .collect();
    ArModelFile::new(entries)
}
