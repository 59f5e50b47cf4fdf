//! Student's t quantile, the one implementation (through `statrs`) behind the run statistics'
//! intervals ([`super::metrics`]), the fitted slopes' intervals ([`super::slope`]) and the error
//! bars of the compare pages.

use statrs::distribution::{ContinuousCDF, StudentsT};

/// Degrees of freedom above this are evaluated at this value by [`student_t_quantile`]; the
/// quantile then differs from the normal limit by less than 1e-5.
pub const MAX_DOF: f64 = 1e6;

/// Quantile of Student's t distribution: the `t` with `P(T <= t) = p` for `dof` degrees of freedom
/// (`dof` need not be an integer; values above [`MAX_DOF`] are evaluated at `MAX_DOF`), from
/// `statrs` (its inverse CDF over the regularized incomplete beta function).
///
/// # Panics
/// If `p` is not strictly between 0 and 1 or `dof` is not positive.
pub fn student_t_quantile(p: f64, dof: f64) -> f64 {
    assert!(p > 0.0 && p < 1.0 && dof > 0.0, "student_t_quantile: need 0 < p < 1 and dof > 0, got p={p}, dof={dof}");
    StudentsT::new(0.0, 1.0, dof.min(MAX_DOF)).map_or(f64::NAN, |t| t.inverse_cdf(p))
}
