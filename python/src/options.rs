//! Checking keyword arguments: each error is a `ValueError` that names the argument and says
//! what it takes (wrong types are refused by PyO3 with a `TypeError` that names it too).

use fairmesh::fairing::BoundaryMode;
use pyo3::exceptions::PyValueError;
use pyo3::PyResult;

/// A count: `value` as a usize, refused when negative.
pub fn count(name: &str, value: i64) -> PyResult<usize> {
    usize::try_from(value)
        .map_err(|_| PyValueError::new_err(format!("{name} must be 0 or more, not {value}")))
}

/// A finite number in `range` (inclusive), described as `what` in the error.
pub fn number_in(name: &str, value: f64, low: f64, high: f64) -> PyResult<f64> {
    if value.is_finite() && (low..=high).contains(&value) {
        Ok(value)
    } else {
        Err(PyValueError::new_err(format!(
            "{name} must be a number from {low} to {high}, not {value}"
        )))
    }
}

/// A finite number of `low` or more.
pub fn at_least(name: &str, value: f64, low: f64) -> PyResult<f64> {
    if value.is_finite() && value >= low {
        Ok(value)
    } else {
        Err(PyValueError::new_err(format!(
            "{name} must be a finite number of {low} or more, not {value}"
        )))
    }
}

/// A finite number.
pub fn finite(name: &str, value: f64) -> PyResult<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PyValueError::new_err(format!(
            "{name} must be a finite number, not {value}"
        )))
    }
}

/// One of `choices` (compared without case; `_` stands for `-`), as its index.
pub fn choice(name: &str, value: &str, choices: &[&str]) -> PyResult<usize> {
    choice_or_old_name(name, value, choices, &[])
}

/// [`choice`], also accepting the old names of `old_names` (name, index of the choice it means);
/// the error lists only the current names.
pub fn choice_or_old_name(
    name: &str,
    value: &str,
    choices: &[&str],
    old_names: &[(&str, usize)],
) -> PyResult<usize> {
    let wanted = value.to_ascii_lowercase().replace('_', "-");
    let old = old_names
        .iter()
        .find(|(old, _)| *old == wanted)
        .map(|&(_, index)| index);
    choices
        .iter()
        .position(|c| *c == wanted)
        .or(old)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "{name} must be one of {}, not {value:?}",
                choices
                    .iter()
                    .map(|c| format!("{c:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
}

/// `boundary`: "curve" or "fixed".
pub fn boundary(value: &str) -> PyResult<BoundaryMode> {
    Ok(match choice("boundary", value, &["curve", "fixed"])? {
        0 => BoundaryMode::Curve,
        _ => BoundaryMode::Fixed,
    })
}

/// `threads`: None (the shared pool, every core) or how many threads the call runs on (1 or
/// more), in a pool of its own.
pub fn threads(value: Option<i64>) -> PyResult<Option<usize>> {
    match value {
        None => Ok(None),
        Some(n) if n >= 1 => Ok(Some(n as usize)),
        Some(n) => Err(PyValueError::new_err(format!(
            "threads must be 1 or more (or None for every core), not {n}"
        ))),
    }
}
