//! Surfaces evaluated for the build and for `lensc analyse` and `lensc
//! sample`: the backend (the JIT, or the interpreter behind it), a
//! declared surface lowered by name, its analysis, and samples of it.

use lensc_grammar::{Diagnostic, Severity};
use lensc_lang::Checked;
use lensc_runtime::surface::ir::SurfaceFn;

pub mod compiled;

/// Where `lensc sample` evaluates a surface.
pub enum SamplePoints {
    /// n × n over the domain's bounding box, points inside the domain.
    Grid(usize),
    /// n points from the centre of the domain to its edge along +x.
    Radial(usize),
    /// Given points (mm).
    Points(Vec<(f64, f64)>),
}

/// One sample: x, y, z (mm), dz/dx, dz/dy, curvature along x and y (1/mm).
pub type Sample = [f64; 7];

/// The evaluator of a surface.
#[derive(Clone, Copy, Debug, serde::Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    /// Compiled to machine code by cranelift.
    Jit,
    /// The reference interpreter (cranelift refused the tape).
    Interpreter,
}

/// The backend that evaluates surfaces: a JIT kernel, or the reference
/// interpreter should cranelift refuse the tape (they agree to 1e-13, see
/// `lensc_runtime::surface::conformance` and tests/it/surface_kinds.rs).
/// The second value names the backend used (reports carry it). A tape
/// compiled before is not compiled again (`compiled`).
pub fn evaluator(
    tape: &lensc_runtime::surface::ir::SurfaceTape,
) -> (
    Box<dyn lensc_runtime::surface::ir::SurfaceFn + Sync>,
    Backend,
) {
    match compiled::COMPILED.kernel(tape) {
        Ok(j) => (Box::new(j), Backend::Jit),
        Err(_) => (
            Box::new(lensc_runtime::surface::ir::Interpreter::new(tape)),
            Backend::Interpreter,
        ),
    }
}

/// The declared surface `name`, lowered to IR, or a message saying why not.
pub fn declared_surface(
    c: &Checked,
    name: &str,
) -> Result<lensc_lang::lower::surface::LoweredSurface, String> {
    let Some(obj) = c.checked.declarations.get(name) else {
        let mut names: Vec<&str> = c
            .checked
            .declarations
            .iter()
            .filter(|(_, o)| o.kind.category == lensc_lang::schema::Category::Surface)
            .map(|(n, _)| n.as_str())
            .collect();
        names.sort_unstable();
        return Err(format!(
            "no surface `{name}` (surfaces: {})",
            if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            }
        ));
    };
    if obj.kind.category != lensc_lang::schema::Category::Surface {
        return Err(format!(
            "`{name}` is {}, not a surface",
            obj.kind.category.noun()
        ));
    }
    lensc_lang::lower::surface::lower_surface(obj).map_err(|e| {
        format!(
            "`{name}` cannot be evaluated yet: {}",
            crate::diagnostics::lowering_words(&e)
        )
    })
}

/// Evaluates a declared surface at the requested points.
pub fn sample(c: &Checked, surface: &str, at: &SamplePoints) -> Result<Vec<Sample>, String> {
    let lowered = declared_surface(c, surface)?;
    let (f, _) = evaluator(&lowered.tape);
    let domain = lowered.domain;
    let ((x0, x1), (y0, y1)) = domain.bounds();
    let (xs, ys): (Vec<f64>, Vec<f64>) = match at {
        SamplePoints::Grid(n) => {
            let n = (*n).max(1);
            let step = |a: f64, b: f64, i: usize| {
                if n == 1 {
                    0.5 * (a + b)
                } else {
                    a + (b - a) * i as f64 / (n - 1) as f64
                }
            };
            (0..n)
                .flat_map(|j| (0..n).map(move |i| (step(x0, x1, i), step(y0, y1, j))))
                .filter(|&(x, y)| domain.contains(x, y))
                .unzip()
        }
        SamplePoints::Radial(n) => {
            let n = (*n).max(1);
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            (0..n)
                .map(|i| {
                    (
                        if n == 1 {
                            cx
                        } else {
                            cx + (x1 - cx) * i as f64 / (n - 1) as f64
                        },
                        cy,
                    )
                })
                .unzip()
        }
        SamplePoints::Points(p) => p.iter().copied().unzip(),
    };
    let mut out = vec![0.0; 6 * xs.len()];
    f.eval_batch(&xs, &ys, &mut out);
    Ok((0..xs.len())
        .map(|i| {
            let o = &out[6 * i..6 * i + 6];
            [
                xs[i],
                ys[i],
                o[0],
                o[1],
                o[2],
                lensc_runtime::surface::analysis::curvature_x(o),
                lensc_runtime::surface::analysis::curvature_y(o),
            ]
        })
        .collect())
}

/// The points per side of the grid a surface is sampled on for where it
/// has no value (about 800 points inside a circle: a millisecond with the
/// interpreter).
pub const UNDEFINED_GRID: usize = 33;

/// The first point of an `n` × `n` grid over the surface's aperture
/// where its sag has no finite value (the square root of a negative
/// number, a logarithm of one, a division by zero), in mm. Each point is
/// drawn in towards the aperture's centre by a millionth, so a surface
/// defined exactly to its rim (a hemisphere's `sqrt(R² − r²)`) passes.
pub fn undefined_at(
    l: &lensc_lang::lower::surface::LoweredSurface,
    n: usize,
) -> Option<(f64, f64)> {
    let ((x0, x1), (y0, y1)) = l.domain.bounds();
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let n = n.max(2);
    let inward = 1.0 - 1e-6;
    let at = |a: f64, b: f64, c: f64, i: usize| {
        c + (a + (b - a) * i as f64 / (n - 1) as f64 - c) * inward
    };
    let (xs, ys): (Vec<f64>, Vec<f64>) = (0..n)
        .flat_map(|j| (0..n).map(move |i| (at(x0, x1, cx, i), at(y0, y1, cy, j))))
        .filter(|&(x, y)| l.domain.contains(x, y))
        .unzip();
    let f = lensc_runtime::surface::ir::Interpreter::new(&l.tape);
    let mut out = vec![0.0; 6 * xs.len()];
    f.eval_batch(&xs, &ys, &mut out);
    (0..xs.len())
        .find(|&i| !out[6 * i].is_finite())
        .map(|i| (xs[i], ys[i]))
}

/// Every declared surface (in declaration order) that has no value
/// somewhere over its aperture, as a diagnostic of `severity`: E0187 for
/// `lensc check` and `build`, W0022 for `lensc analyse` and `sample`
/// (which show such points as NaN). `only` limits it to one surface.
pub fn undefined_surfaces(c: &Checked, severity: Severity, only: Option<&str>) -> Vec<Diagnostic> {
    let mut surfaces: Vec<(&String, &std::rc::Rc<lensc_lang::value::Object>)> = c
        .checked
        .declarations
        .iter()
        .filter(|(n, o)| {
            o.kind.category == lensc_lang::schema::Category::Surface
                && only.is_none_or(|only| only == n.as_str())
        })
        .collect();
    surfaces.sort_by_key(|(n, o)| (o.file.0, o.head.start, n.as_str()));
    let mut found = Vec::new();
    for (name, obj) in surfaces {
        let Ok(l) = lensc_lang::lower::surface::lower_surface(obj) else {
            continue;
        };
        let Some((x, y)) = undefined_at(&l, UNDEFINED_GRID) else {
            continue;
        };
        let (code, make): (_, fn(_, _, _, _) -> Diagnostic) = match severity {
            Severity::Error => (lensc_lang::codes::SURFACE_UNDEFINED, Diagnostic::error),
            Severity::Warning => (
                lensc_lang::codes::SURFACE_UNDEFINED_WARNING,
                Diagnostic::warning,
            ),
        };
        found.push(
            make(
                code,
                format!(
                    "the surface `{name}` has no value at x = {x:.6} mm, y = {y:.6} mm, inside its aperture"
                ),
                obj.file,
                obj.head,
            )
            .with_label("no value over part of this surface's aperture")
            .with_help("check the formula's square roots, logarithms and divisions over the whole aperture, or make the aperture smaller"),
        );
    }
    found
}
