//! Tests of the spiral's lowering: where it ends.

use super::past_axis;
use lensc_runtime::surface::ir::SurfaceFn;

/// A plane z = g·x + h·y (its six outputs: z, the slopes, no curvature).
struct Plane(f64, f64);

impl SurfaceFn for Plane {
    fn eval_batch(&self, xs: &[f64], ys: &[f64], out: &mut [f64]) {
        for (i, (x, y)) in xs.iter().zip(ys).enumerate() {
            out[6 * i..6 * i + 6].copy_from_slice(&[
                self.0 * x + self.1 * y,
                self.0,
                self.1,
                0.0,
                0.0,
                0.0,
            ]);
        }
    }
}

#[test]
fn a_spiral_over_a_slope_at_the_axis_ends_past_it() {
    // Issue #29: the hex array's lenslet at x = −0.25 mm (R 3 mm) slopes
    // 0.0836 at the axis; a 0.496 mm nose reaches the axis from the uphill
    // rays only with its centre 41.3 µm past it.
    let g = 0.25 / (9.0f64 - 0.0625).sqrt();
    let past = past_axis(&Plane(g, 0.0), 0.496, 3.0, 1e-6);
    assert!(
        (past - 0.496 * g / (1.0 + g * g).sqrt()).abs() < 1e-12,
        "{past}"
    );
    assert!((past - 0.0413).abs() < 1e-4, "{past}");
    // The same slope along y, and either sign.
    assert_eq!(past, past_axis(&Plane(0.0, -g), 0.496, 3.0, 1e-6));
    // Level at the axis (an axisymmetric part, an array's land): it ends
    // there, as before; and never past half its own start.
    assert_eq!(past_axis(&Plane(0.0, 0.0), 0.496, 3.0, 1e-6), 0.0);
    assert_eq!(past_axis(&Plane(g, 0.0), 0.496, 0.05, 1e-6), 0.025);
    // A slope whose reach is below the resolution: nothing to cut.
    assert_eq!(past_axis(&Plane(1e-7, 0.0), 0.496, 3.0, 1e-6), 0.0);
}
