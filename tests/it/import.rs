//! `lensc import`: every prescription in tests/import/ (Zemax `.zmx`, one
//! of them UTF-16 as OpticStudio writes them, and optiland JSON, each
//! citing where its numbers come from) imports to a file `lensc check`
//! accepts, with one `surface` per optical surface and exactly the expected
//! warnings; and each imported surface, lowered and evaluated by lensc's
//! own interpreter, has the height of the prescription's sag written out
//! independently here (in the file's own units, then scaled to mm) at
//! many points, to 1e-12 relative.

use std::path::Path;

use lensc_build::driver;
use lensc_lang::loader::RealFs;
use lensc_runtime::surface::ir::{Interpreter, SurfaceFn};

use crate::common::{lensc, root, text};

/// A surface as the designer's file states it, in the file's lens units.
#[derive(Clone, Copy)]
enum Sag {
    /// Radius (infinite: flat), conic, (power, coefficient) terms.
    Rotational(f64, f64, &'static [(i32, f64)]),
    /// Rx, Ry, kx, ky.
    Biconic(f64, f64, f64, f64),
    /// Ry, k, radius of rotation (0: none), terms in y.
    Toroid(f64, f64, f64, &'static [(i32, f64)]),
    /// Zemax's extended polynomial: R, k, normalisation radius, terms
    /// (i, j, A) of A (x/norm)^i (y/norm)^j.
    ExtendedPolynomial(f64, f64, f64, &'static [(i32, i32, f64)]),
    /// Zemax's Zernike standard sag: R, k, normalisation radius, and the
    /// coefficients of Noll's Z4, Z6, Z7 and Z11.
    ZernikeStandard(f64, f64, f64, [f64; 4]),
}

impl Sag {
    /// The designer's sag z(x, y): the textbook formulas.
    fn at(self, x: f64, y: f64) -> f64 {
        let conic = |r: f64, k: f64, s: f64| {
            if r.is_infinite() {
                0.0
            } else {
                s / (r * (1.0 + (1.0 - (1.0 + k) * s / (r * r)).sqrt()))
            }
        };
        let poly =
            |t: &[(i32, f64)], u: f64| t.iter().map(|(p, a)| a * u.abs().powi(*p)).sum::<f64>();
        match self {
            Sag::Rotational(r, k, t) => {
                let s = x * x + y * y;
                conic(r, k, s) + poly(t, s.sqrt())
            }
            Sag::Biconic(rx, ry, kx, ky) => {
                let (cx, cy) = (1.0 / rx, 1.0 / ry);
                (cx * x * x + cy * y * y)
                    / (1.0
                        + (1.0 - (1.0 + kx) * cx * cx * x * x - (1.0 + ky) * cy * cy * y * y)
                            .sqrt())
            }
            Sag::ExtendedPolynomial(r, k, norm, t) => {
                let (u, v) = (x / norm, y / norm);
                conic(r, k, x * x + y * y)
                    + t.iter()
                        .map(|(i, j, a)| a * u.powi(*i) * v.powi(*j))
                        .sum::<f64>()
            }
            Sag::ZernikeStandard(r, k, norm, [z4, z6, z7, z11]) => {
                // As OpticStudio's Zernike Standard listing writes them.
                let (p, a) = ((x * x + y * y).sqrt() / norm, y.atan2(x));
                conic(r, k, x * x + y * y)
                    + z4 * 3f64.sqrt() * (2.0 * p * p - 1.0)
                    + z6 * 6f64.sqrt() * p * p * (2.0 * a).cos()
                    + z7 * 8f64.sqrt() * (3.0 * p.powi(3) - 2.0 * p) * a.sin()
                    + z11 * 5f64.sqrt() * (6.0 * p.powi(4) - 6.0 * p * p + 1.0)
            }
            Sag::Toroid(ry, k, rr, t) => {
                let zy = conic(ry, k, y * y) + poly(t, y);
                if rr == 0.0 {
                    zy
                } else {
                    // rr − sign(rr) sqrt((rr − zy)² − x²), without its cancellation.
                    (2.0 * rr * zy - zy * zy + x * x)
                        / (rr + rr.signum() * ((rr - zy).powi(2) - x * x).sqrt())
                }
            }
        }
    }
}

/// An imported surface expected in the output.
struct Want {
    name: &'static str,
    sag: Sag,
    /// Semi-diameter in lens units.
    semi_diameter: f64,
    /// A lens's rear surface: the tool meets it with the part turned over.
    rear: bool,
}

const fn want(name: &'static str, sag: Sag, semi_diameter: f64, rear: bool) -> Want {
    Want {
        name,
        sag,
        semi_diameter,
        rear,
    }
}

/// optiland's AsphericSinglet: the front asphere (the back is flat).
const SINGLET: &[Want] = &[want(
    "surface_1",
    Sag::Rotational(
        20.0,
        0.0,
        &[(2, -2.248851e-4), (4, -4.690412e-6), (6, -6.404376e-8)],
    ),
    10.0,
    false,
)];

const COOKE: &[Want] = &[
    want("surface_1", Sag::Rotational(22.01359, 0.0, &[]), 8.0, false),
    want(
        "surface_2",
        Sag::Rotational(-435.76044, 0.0, &[]),
        7.5,
        true,
    ),
    want(
        "surface_3",
        Sag::Rotational(-22.21328, 0.0, &[]),
        5.0,
        false,
    ),
    want("surface_4", Sag::Rotational(20.29192, 0.0, &[]), 4.6, true),
    want("surface_5", Sag::Rotational(79.68360, 0.0, &[]), 6.5, false),
    want("surface_6", Sag::Rotational(-18.39533, 0.0, &[]), 6.5, true),
];

/// The expected surfaces, warnings and lens unit (in mm) of each file.
fn cases() -> Vec<(&'static str, Vec<Want>, Vec<&'static str>, f64)> {
    let cone = want(
        "surface_1",
        // z = tan(0.5°) r: the axicon's cone.
        Sag::Rotational(f64::INFINITY, 0.0, &[(1, 0.008_726_867_790_758_79)]),
        11.43,
        false,
    );
    assert!((0.5f64.to_radians().tan() - 0.008_726_867_790_758_79).abs() < 1e-17);
    let bench = vec![
        want(
            "surface_1",
            Sag::Rotational(1.0 / 0.8, -0.6, &[(3, 1.2e-2), (4, -3.0e-3), (5, 4.0e-4)]),
            0.3,
            false,
        ),
        want(
            "surface_2",
            Sag::Biconic(-1.6, -1.0 / 0.5, -1.2, 0.3),
            0.3,
            true,
        ),
        want(
            "surface_3",
            Sag::Toroid(1.0 / 0.4, -0.5, 3.0, &[(4, 2.0e-3), (6, -1.0e-4)]),
            0.4,
            false,
        ),
        want(
            "surface_4",
            Sag::Toroid(-1.0 / 0.25, 0.0, 0.0, &[(4, 5.0e-3)]),
            0.4,
            true,
        ),
        want(
            "surface_6",
            Sag::ExtendedPolynomial(
                10.0,
                0.0,
                0.4,
                &[(1, 0, 1e-3), (2, 0, 2e-3), (1, 1, -1e-3), (0, 2, 5e-4)],
            ),
            0.4,
            false,
        ),
        want(
            "surface_7",
            Sag::ZernikeStandard(-10.0, 0.0, 0.4, [2e-4, -1e-4, 5e-5, 3e-5]),
            0.4,
            true,
        ),
    ];
    vec![
        (
            "aspheric_singlet.zmx",
            SINGLET.iter().map(copy).collect(),
            vec![],
            1.0,
        ),
        (
            "aspheric_singlet.json",
            SINGLET.iter().map(copy).collect(),
            vec![],
            1.0,
        ),
        (
            "cooke_triplet.zmx",
            COOKE.iter().map(copy).collect(),
            vec![],
            1.0,
        ),
        (
            "cooke_triplet.json",
            COOKE.iter().map(copy).collect(),
            vec![],
            1.0,
        ),
        ("axicon_odd_asphere.zmx", vec![cone], vec![], 1.0),
        (
            "test_bench.zmx",
            bench,
            vec!["W0016", "W0016", "W0018", "W0016", "W0015"],
            25.4,
        ),
    ]
}

fn copy(w: &Want) -> Want {
    want(w.name, w.sag, w.semi_diameter, w.rear)
}

/// The codes of the warnings on stderr, in order.
fn codes(stderr: &str) -> Vec<String> {
    stderr
        .lines()
        .filter_map(|l| {
            l.strip_prefix('[')?
                .split_once(']')
                .map(|(c, _)| c.to_string())
        })
        .collect()
}

#[test]
fn every_prescription_imports_checks_and_has_the_designers_sag() {
    let dir = root().join("tests/import");
    let out = tempfile::tempdir().expect("tmp");
    let mut compared = 0;
    for (file, wants, warnings, unit) in cases() {
        let lens = out.path().join(file.replace('.', "_") + ".lens");
        let lens_arg = lens.to_str().expect("UTF-8 path");
        let run = lensc(&dir, &["import", file, "-o", lens_arg]);
        let stderr = text(&run.stderr);
        assert_eq!(run.status.code(), Some(0), "{file}:\n{stderr}");
        assert_eq!(codes(&stderr), warnings, "{file}:\n{stderr}");
        let check = lensc(out.path(), &["check", lens_arg]);
        assert_eq!(
            check.status.code(),
            Some(0),
            "{file}: {}",
            text(&check.stderr)
        );
        assert!(
            !text(&check.stderr).contains('['),
            "{file}: {}",
            text(&check.stderr)
        );

        let written = std::fs::read_to_string(&lens).expect("written");
        let declared = written
            .lines()
            .filter(|l| l.starts_with("surface "))
            .count();
        assert_eq!(declared, wants.len(), "{file}:\n{written}");
        compared += compare_sags(file, &lens, &wants, unit);
    }
    assert!(compared > 10_000, "only {compared} points compared");
}

/// Evaluates each wanted surface of the imported file with the interpreter
/// and compares it with the designer's sag; returns the points compared.
fn compare_sags(file: &str, lens: &Path, wants: &[Want], unit: f64) -> usize {
    let checked = driver::check_path(&RealFs, lens).expect("read");
    let mut n = 0;
    let mut worst: f64 = 0.0;
    for w in wants {
        let l = driver::declared_surface(&checked, w.name)
            .unwrap_or_else(|e| panic!("{file} {}: {e}", w.name));
        let sd = w.semi_diameter * unit;
        let ((x0, x1), (y0, y1)) = l.domain.bounds();
        for b in [x1, y1, -x0, -y0] {
            assert!(
                (b - sd).abs() <= 1e-12 * sd,
                "{file} {}: aperture {b} mm, want {sd} mm",
                w.name
            );
        }
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for i in 0..=80 {
            for a in 0..12 {
                let (r, t) = (
                    sd * i as f64 / 80.0,
                    a as f64 * std::f64::consts::PI / 6.0 + 0.1,
                );
                let (x, y) = (r * t.cos(), r * t.sin());
                if l.domain.contains(x, y) {
                    xs.push(x);
                    ys.push(y);
                }
            }
        }
        let mut got = vec![0.0; 6 * xs.len()];
        Interpreter::new(&l.tape).eval_batch(&xs, &ys, &mut got);
        for (k, (&x, &y)) in xs.iter().zip(&ys).enumerate() {
            // In the file's units, scaled to mm; the tool's height is the
            // designer's sag negated (light into the material from the
            // tool's side) or, for a rear surface turned over about y, the
            // sag itself at (-x, y).
            let designer = if w.rear {
                unit * w.sag.at(-x / unit, y / unit)
            } else {
                -unit * w.sag.at(x / unit, y / unit)
            };
            let z = got[6 * k];
            if designer != 0.0 {
                worst = worst.max((z - designer).abs() / designer.abs());
            }
            assert!(
                (z - designer).abs() <= 1e-12 * designer.abs() + 1e-15,
                "{file} {} at ({x}, {y}): lensc {z:e} mm, prescription {designer:e} mm",
                w.name
            );
        }
        n += xs.len();
    }
    eprintln!("{file}: {n} points, largest relative difference {worst:.1e}");
    n
}

#[test]
fn the_imported_cooke_triplet_is_the_snapshot() {
    let run = lensc(
        &root().join("tests/import"),
        &["import", "cooke_triplet.zmx"],
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    insta::with_settings!({ snapshot_path => "../snapshots/import", prepend_module_to_snapshot => false, omit_expression => true }, {
        insta::assert_snapshot!("cooke_triplet_zmx", text(&run.stdout));
    });
}

#[test]
fn unsupported_surfaces_are_named_in_the_output_too() {
    let run = lensc(&root().join("tests/import"), &["import", "test_bench.zmx"]);
    let lens = text(&run.stdout);
    for named in [
        "surface 5 (COORDBRK) \"tilt\": not imported",
        "surface 8 (BINARY_2) \"grating\": not imported, lensc does not import Zemax BINARY_2 surfaces",
        "Not imported: extra data 1 = 3.",
        "Not imported: extra data 20 = 0.00001 (past the 11 terms extra data 1 counts).",
    ] {
        assert!(lens.contains(named), "no `{named}` in\n{lens}");
    }
}

#[test]
fn a_file_that_cannot_be_imported_writes_nothing() {
    let dir = tempfile::tempdir().expect("tmp");
    let cases: [(&str, &[u8], &str); 5] = [
        ("nsc.zmx", b"MODE NSC\nSURF 0\n", "E0352"),
        (
            "tiny.zmx",
            b"SURF 0\nSURF 1\n  CURV 1e-320\n  DIAM 4\nSURF 2\n",
            "E0353",
        ),
        ("bad.zmx", b"SURF 0\n  CURV 1/20\n", "E0350"),
        (
            "flat.zmx",
            b"SURF 0\nSURF 1\n  CURV 0\n  DIAM 4\nSURF 2\n",
            "E0351",
        ),
        ("cut.json", b"{\"surface_group\": {\"surfaces\": [", "E0350"),
    ];
    for (name, bytes, code) in cases {
        std::fs::write(dir.path().join(name), bytes).expect("write");
        let run = lensc(dir.path(), &["import", name, "-o", "out.lens"]);
        assert_eq!(run.status.code(), Some(1), "{name}");
        assert!(
            text(&run.stderr).contains(&format!("[{code}]")),
            "{name}: {}",
            text(&run.stderr)
        );
        assert!(!dir.path().join("out.lens").exists(), "{name} wrote a file");
    }
}

/// The imported file gets the mode any file the user creates gets, 0666
/// less the umask (not a temporary file's private 0600).
#[cfg(unix)]
#[test]
fn the_written_file_has_the_users_usual_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::copy(
        root().join("tests/import/cooke_triplet.zmx"),
        dir.path().join("c.zmx"),
    )
    .expect("copy");
    for (umask, mode) in [("022", 0o644), ("002", 0o664), ("077", 0o600)] {
        let out = dir.path().join(format!("c{umask}.lens"));
        let run = std::process::Command::new("sh")
            .current_dir(dir.path())
            .arg("-c")
            .arg(format!(
                "umask {umask} && exec \"$0\" import c.zmx -o {}",
                out.display()
            ))
            .arg(env!("CARGO_BIN_EXE_lensc"))
            .output()
            .expect("run");
        assert!(run.status.success(), "{}", text(&run.stderr));
        let got = std::fs::metadata(&out)
            .expect("written")
            .permissions()
            .mode()
            & 0o777;
        assert_eq!(got, mode, "umask {umask}: {got:o}");
    }
}
