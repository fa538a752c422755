//! The rules that tie several parameters of one kind together: one
//! function per rule, run once a kind's parameters have checked.

use lensc_grammar::Diagnostic;
use lensc_grammar::suggest::did_you_mean;
use lensc_runtime::moves::Plane;

use super::{Checker, trim_num};
use crate::codes;
use crate::domain::aperture_radius;
use crate::value::{self, Field, Object, Value};

/// The most lenslets an array may have in all (a thousand by a
/// thousand): the lowering lists every lenslet's centre.
pub const MAX_LENSLETS: f64 = 1e6;

impl<'a> Checker<'a> {
    /// Rules that tie several parameters of one kind together.
    pub(super) fn kind_rules(&mut self, o: &Object) -> bool {
        match o.kind.name {
            "conic" | "sphere" | "asphere" | "cylinder" | "acylinder" | "toroid" | "qbfs"
            | "qcon" => self.conic_limit(o),
            "annulus" => self.annulus_order(o),
            "wrap" => self.wrap_fits_roller(o),
            "grid" | "hex_grid" => self.lenslets_bounded(o),
            "zernike" => self.fringe_terms(o),
            "ellipsoid" => self.ellipsoid_rim(o),
            "profile_turning" => self.profile_turning_passes(o),
            "gcode" => self.arc_planes_named(o),
            "fts_lathe" => self.servo_axis_whole(o),
            _ => true,
        }
    }

    /// E0127: a rotational surface's aperture stays inside the edge of its
    /// conic, r < R/sqrt(1 + k).
    fn conic_limit(&mut self, o: &Object) -> bool {
        let (Some(r), Some(ap)) = (
            value::num(&o.fields, "radius").map(f64::abs),
            value::object(&o.fields, "aperture"),
        ) else {
            return true;
        };
        let k = value::num(&o.fields, "conic").unwrap_or(0.0);
        let Some(ar) = aperture_radius(ap) else {
            return true;
        };
        let Some(limit) = lensc_runtime::surface::RotationalSurface::conic_limit(r, k) else {
            return true;
        };
        if ar >= limit {
            let ap_field = value::field(&o.fields, "aperture").expect("aperture");
            self.err(
                Diagnostic::error(
                    codes::CONIC_DOMAIN,
                    format!("the aperture (radius {} mm) reaches beyond the edge of this conic, which ends at r = {} mm", trim_num(ar), trim_num(limit)),
                    ap_field.file,
                    ap_field.span,
                )
                .with_label(format!("the conic is only defined for r < {} mm", trim_num(limit)))
                .with_note(o.file, o.head, "R/sqrt(1 + k) bounds this conic")
                .with_help("reduce the aperture, or check the sign of the conic constant"),
            );
            return false;
        }
        true
    }

    /// An annulus's inner radius lies inside its outer radius.
    fn annulus_order(&mut self, o: &Object) -> bool {
        let (Some(inner), Some(outer)) = (
            value::num(&o.fields, "inner"),
            value::num(&o.fields, "outer"),
        ) else {
            return true;
        };
        if inner >= outer {
            let f = value::field(&o.fields, "inner").expect("inner");
            self.err(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    format!(
                        "the annulus's inner radius ({} mm) is not inside its outer radius ({} mm)",
                        trim_num(inner),
                        trim_num(outer)
                    ),
                    f.file,
                    f.span,
                )
                .with_label("not below `outer`"),
            );
            return false;
        }
        true
    }

    /// E0126: each of a dialect's `arc_planes` names a plane (`xy`, `zx`,
    /// `yz`); lowering has no arcs for another word, so it would drop the
    /// word and the arcs in that plane without a word.
    fn arc_planes_named(&mut self, o: &Object) -> bool {
        let Some(f) = value::field(&o.fields, "arc_planes") else {
            return true;
        };
        let Value::List(items) = &f.value else {
            return true;
        };
        let names = Plane::ALL.map(Plane::name);
        let mut ok = true;
        for (v, span) in items {
            let Value::Str(s) = v else { continue };
            if Plane::from_name(s).is_some() {
                continue;
            }
            ok = false;
            let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
            let help = match did_you_mean(s, names.iter().copied()) {
                Some(n) => format!("did you mean \"{n}\"?"),
                None => "the planes are \"xy\" (G17), \"zx\" (G18) and \"yz\" (G19)".into(),
            };
            self.err(
                Diagnostic::error(
                    codes::UNKNOWN_WORD,
                    format!("`arc_planes` cannot hold \"{s}\": it is not a plane"),
                    f.file,
                    *span,
                )
                .with_label(format!("expected one of {}", quoted.join(", ")))
                .with_help(help),
            );
        }
        ok
    }

    /// E0121: a fast tool servo given its own axis states both its
    /// letter and its velocity limit: a letter with no limit would write
    /// moves no check holds, a limit with no letter names no axis.
    fn servo_axis_whole(&mut self, o: &Object) -> bool {
        let Some(f) = value::field(&o.fields, "fast_axis") else {
            return true;
        };
        let Value::Block(fields) = &f.value else {
            return true;
        };
        let (letter, velocity) = (
            value::field(fields, "letter"),
            value::field(fields, "max_velocity"),
        );
        let (given, missing, help) = match (letter, velocity) {
            (Some(l), None) => (
                l,
                "max_velocity",
                "state the servo's velocity limit as its axis, `max_velocity: …` (LinuxCNC's `[AXIS_W] MAX_VELOCITY`)",
            ),
            (None, Some(v)) => (
                v,
                "letter",
                "state the letter the control gives the servo, `letter: W` (or U, V); without one the servo is written on Z and held to `max_feed`",
            ),
            _ => return true,
        };
        self.err(
            Diagnostic::error(
                codes::MISSING_PARAMETER,
                format!(
                    "the fast axis's `{}` needs its `{missing}`: the servo as an axis of its own is given by both",
                    given.name
                ),
                given.file,
                given.name_span,
            )
            .with_label(format!("stated without `{missing}`"))
            .with_help(help),
        );
        false
    }

    /// E0123: an array has at most `MAX_LENSLETS` lenslets in all (each
    /// count is bounded alone, but their product, and a hex grid's rows,
    /// were not: `count_y: 4294967297` rows made `lensc check` ask for
    /// 34 GB for the lenslets' centres and abort).
    fn lenslets_bounded(&mut self, o: &Object) -> bool {
        let (Some(nx), Some(ny)) = (
            value::num(&o.fields, "count_x"),
            value::num(&o.fields, "count_y"),
        ) else {
            return true;
        };
        // A hex grid's rows may be fractional: the lowering places
        // ceil(count_y) rows.
        let lenslets = nx.ceil().max(1.0) * ny.ceil().max(1.0);
        if lenslets <= MAX_LENSLETS {
            return true;
        }
        let at = value::field(&o.fields, "count_y").expect("count_y");
        self.err(
            Diagnostic::error(
                codes::OUT_OF_RANGE,
                format!(
                    "this array has {} lenslets ({} by {}), more than the {} an array may have",
                    trim_num(lenslets),
                    trim_num(nx.ceil()),
                    trim_num(ny.ceil()),
                    trim_num(MAX_LENSLETS)
                ),
                at.file,
                at.span,
            )
            .with_label("too many lenslets")
            .with_note(o.file, o.head, "count_x times count_y lenslets")
            .with_help("make several jobs of smaller arrays, or check the counts"),
        );
        false
    }

    /// E0134: a design wrapped onto a roller is no longer than the roller's
    /// circumference (within 1 µm); a shorter one leaves a gap (a warning).
    fn wrap_fits_roller(&mut self, o: &Object) -> bool {
        let f = &o.fields;
        let (Some(design), Some(roller)) = (value::object(f, "surface"), value::object(f, "onto"))
        else {
            return true;
        };
        let Some(radius) = value::num(&roller.fields, "radius") else {
            return true;
        };
        let length = crate::domain::surface_domain(design).map(|d| match d {
            lensc_runtime::surface::analysis::Domain::Rect { y, .. } => y.1 - y.0,
            lensc_runtime::surface::analysis::Domain::Circle { radius }
            | lensc_runtime::surface::analysis::Domain::Annulus { outer: radius, .. } => {
                2.0 * radius
            }
        });
        let Some(length) = length else { return true };
        let at = value::field(f, "onto").expect("onto");
        // The rule and its 1 µm tolerance are the runtime's `check_wrap`,
        // which the roller planner runs again as its precondition.
        use lensc_runtime::plan::roller::{RollerError, check_wrap};
        match check_wrap(radius, length) {
            Err(RollerError::Overlap { circumference, .. }) => {
                self.err(
                    Diagnostic::error(
                        codes::WRAP_OVERLAP,
                        format!("the design is {} mm long around the roller, more than its circumference 2π·{} = {} mm: it would overlap itself", trim_num(length), trim_num(radius), trim_num(circumference)),
                        at.file,
                        at.span,
                    )
                    .with_label("this roller is too small for the design")
                    .with_help(format!("a roller for this design has radius L/2π = {} mm", trim_num(length / (2.0 * std::f64::consts::PI)))),
                );
                return false;
            }
            Ok(fit) if fit.gap > 0.0 => {
                self.diags.push(
                    Diagnostic::warning(
                        codes::WRAP_GAP,
                        format!("the design is {} mm long around the roller, shorter than its circumference {} mm: a {} mm gap is left", trim_num(length), trim_num(fit.circumference), trim_num(fit.gap)),
                        at.file,
                        at.span,
                    )
                    .with_label("the design does not close around this roller"),
                );
            }
            // A length or radius that is not positive is the range
            // checks' to report.
            _ => {}
        }
        true
    }

    /// Fringe Zernike terms are `Z1` … `Z37`.
    fn fringe_terms(&mut self, o: &Object) -> bool {
        if value::word(&o.fields, "ordering") != Some("fringe") {
            return true;
        }
        let mut ok = true;
        for f in &o.fields {
            if let Some(j) = f.name.strip_prefix('Z').and_then(|j| j.parse::<u32>().ok())
                && !(1..=37).contains(&j)
            {
                self.err(
                    Diagnostic::error(
                        codes::UNKNOWN_PARAMETER,
                        format!("fringe Zernike terms are `Z1` … `Z37`, not `{}`", f.name),
                        f.file,
                        f.name_span,
                    )
                    .with_label("no such fringe term")
                    .with_help("use `ordering: ansi` for more terms (numbered from `Z0`)"),
                );
                ok = false;
            }
        }
        ok
    }

    /// An ellipsoid's aperture stays inside its rim x²/a² + y²/b² < 1.
    fn ellipsoid_rim(&mut self, o: &Object) -> bool {
        let f = &o.fields;
        let (Some(a), Some(b), Some(ap)) = (
            value::num(f, "a"),
            value::num(f, "b"),
            value::object(f, "aperture"),
        ) else {
            return true;
        };
        // The cap is defined inside x²/a² + y²/b² < 1.
        let reach = match ap.kind.name {
            "circle" => aperture_radius(ap).map(|r| r / a.min(b)),
            _ => value::range(&ap.fields, "x")
                .zip(value::range(&ap.fields, "y"))
                .map(|((x0, x1), (y0, y1))| {
                    let (x, y) = (x0.abs().max(x1.abs()), y0.abs().max(y1.abs()));
                    (x * x / (a * a) + y * y / (b * b)).sqrt()
                }),
        };
        if reach.is_some_and(|q| q >= 1.0) {
            let ap_field = value::field(f, "aperture").expect("aperture");
            self.err(
                Diagnostic::error(
                    codes::CONIC_DOMAIN,
                    "the aperture reaches beyond the ellipsoid's rim (x²/a² + y²/b² = 1)",
                    ap_field.file,
                    ap_field.span,
                )
                .with_label(format!(
                    "reaches {} of the way to the rim",
                    trim_num(reach.unwrap_or(0.0))
                ))
                .with_help("keep the aperture inside the semi-axes a and b"),
            );
            return false;
        }
        true
    }

    /// A profile turning with stock says how deep each roughing pass cuts,
    /// and cuts from a larger radius to a smaller one.
    fn profile_turning_passes(&mut self, o: &Object) -> bool {
        let f = &o.fields;
        let stock = value::field(f, "stock_top").or(value::field(f, "stock_allowance"));
        if let Some(at) = stock
            && value::num(f, "depth_of_cut").is_none()
        {
            self.err(
                Diagnostic::error(
                    codes::MISSING_PARAMETER,
                    format!("`{}` gives the stock, but no `depth_of_cut` says how much each roughing pass removes", at.name),
                    at.file,
                    at.span,
                )
                .with_label("the stock")
                .with_help("add `depth_of_cut: …`, a length"),
            );
            return false;
        }
        if let Some(at) = stock
            && value::field(f, "rough_feed").is_none()
        {
            self.err(
                Diagnostic::error(
                    codes::ROUGHING_NEEDS_FEED,
                    format!("`{}` gives the stock, but no `rough_feed` says how fast the roughing passes cut", at.name),
                    at.file,
                    at.span,
                )
                .with_label("the stock")
                .with_help("add `rough_feed: …` (per revolution or per minute); roughing passes no longer run at the finish feed"),
            );
            return false;
        }
        if let (Some(from), Some(to)) = (value::num(&o.fields, "from"), value::num(&o.fields, "to"))
            && from <= to
        {
            let f = value::field(&o.fields, "from").expect("from");
            self.err(
                Diagnostic::error(
                    codes::OUT_OF_RANGE,
                    "the cut must start at a larger radius than it ends",
                    f.file,
                    f.span,
                )
                .with_label("`from` is not above `to`"),
            );
            return false;
        }
        true
    }

    /// The material side is given either by a positive radius and `sense`,
    /// or by a signed radius with `convention: optical`, never both.
    pub(super) fn sign_rule(&mut self, o: &Object) -> bool {
        let f = &o.fields;
        let optical = value::word(f, "convention") == Some("optical");
        let radii: Vec<&Field> = ["radius", "radius_x", "radius_y"]
            .iter()
            .filter_map(|n| value::field(f, n))
            .collect();
        let mut ok = true;
        if optical {
            if let Some(sense) = value::field(f, "sense") {
                let conv = value::field(f, "convention").expect("convention");
                self.err(
                    Diagnostic::error(codes::CONFLICTING_PARAMETERS, "`sense` and `convention: optical` both say which side is material", sense.file, sense.name_span)
                        .with_label("remove this")
                        .with_note(conv.file, conv.span, "the radius's sign says it here")
                        .with_help("with `convention: optical` the sign of the radius gives the side: R > 0 convex, R < 0 concave"),
                );
                ok = false;
            }
            for r in radii {
                if matches!(r.value, Value::Num(v, _) if v == 0.0) {
                    self.err(
                        Diagnostic::error(
                            codes::OUT_OF_RANGE,
                            format!("`{}` cannot be zero", r.name),
                            r.file,
                            r.span,
                        )
                        .with_label("zero radius")
                        .with_help("a flat surface is a `plane`"),
                    );
                    ok = false;
                }
            }
            return ok;
        }
        // Every kind that reads `sense` needs it stated, a plane base with
        // coefficients too: there σ flips every coefficient, so a default
        // would cut the mould of the part as silently as the part.
        if value::field(f, "sense").is_none() {
            let plane_base = radii.is_empty()
                && !o
                    .kind
                    .params
                    .iter()
                    .any(|p| p.name == "radius" && p.required);
            let help = if plane_base {
                "with no `radius` the base is a plane and `sense` signs the terms: `sense: concave` cuts them as written (+z towards the tool), `sense: convex` cuts them negated; or write them as designed with `convention: optical`"
            } else {
                "add `sense: convex` (a dome) or `sense: concave` (a bowl), or give a signed radius with `convention: optical`"
            };
            self.err(
                Diagnostic::error(
                    codes::MISSING_PARAMETER,
                    format!("`{}` is missing `sense`", o.kind.name),
                    o.file,
                    o.head,
                )
                .with_label("needs `sense`")
                .with_help(help),
            );
            ok = false;
        }
        for r in radii {
            if let Value::Num(v, _) = r.value
                && v <= 0.0
            {
                self.err(
                    Diagnostic::error(codes::OUT_OF_RANGE, format!("`{}` must be greater than zero, but it is {} mm", r.name, trim_num(v)), r.file, r.span)
                        .with_label("out of range")
                        .with_help("with `sense`, the radius is a magnitude; a signed radius as in lens design needs `convention: optical` (R < 0 concave)"),
                );
                ok = false;
            }
        }
        ok
    }
}
