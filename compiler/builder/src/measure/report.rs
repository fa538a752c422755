//! The measurement report (`JOB.measure.json`) as typed data: what was
//! measured, how it was registered to the design, the error along the
//! surface normal, the texture after form removal and, for a turned
//! part, the set-up errors. `docs/measure.schema.json` is generated from
//! these types and checked for staleness (the test below).

use schemars::JsonSchema;
use serde::Serialize;

/// The report of one `lensc measure`.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct MeasureReport {
    /// The job whose design the part is held to.
    pub job: String,
    /// The job's surface (its declared name, or its kind written in place).
    pub surface: String,
    pub measurement: Measurement,
    pub coverage: Coverage,
    pub registration: Registration,
    pub form_error: FormError,
    /// Texture after form removal (maps only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture: Option<Texture>,
    /// Why there is no texture, when there is none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture_skipped: Option<String>,
    /// A turned part's set-up errors (lathe jobs with a map or a cloud).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub setup: Option<SetUp>,
    /// Each lenslet of the job's array registered on its own
    /// (`--per-lenslet`), in the array's order: those the map reaches.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lenslets: Option<Lenslets>,
    /// `--lenslet`: the map is one lenslet's field, registered to that
    /// lenslet's design alone; `registration`, `form_error` and `texture`
    /// above are then that lenslet's (its decentre: where its centre lies
    /// from where the field was placed on it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lenslet: Option<LensletField>,
}

/// `--lenslet`: which lenslet the field was held to, where the field was
/// taken to lie and where its registration puts it.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletField {
    /// Its index in its array, from 0 (as `lenslets.each` and the build
    /// report number them), and its row and column, from 0: rows from the
    /// least y, columns along a row from the least x.
    pub index: usize,
    pub row: usize,
    pub column: usize,
    /// Its centre in the design (mm).
    pub centre_mm: [f64; 2],
    /// Which point of the map was placed on the part: its middle pixel,
    /// or the file's origin (`--keep-origin`).
    pub reference: String,
    /// Where that point was taken to lie on the part (mm, the design's x
    /// and y), and what said so: `--at`, or the lenslet's centre.
    pub placed_at_mm: [f64; 2],
    pub placed_by: String,
    /// Where the registration puts that point on the part (mm), the
    /// lenslet taken to sit at its design centre: `placed_at_mm` less the
    /// decentre found (turned by the clocking found, if any).
    pub found_at_mm: [f64; 2],
    /// The share of the lenslet's aperture (by area) under the map's
    /// valid pixels where it was placed, and the least share required
    /// (`--min-valid`).
    pub aperture_covered: f64,
    pub min_covered: f64,
    /// Under 95 % covered: a coded finding (W0037) that the figures
    /// describe only the part of the lenslet measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finding: Option<Finding>,
}

/// `--per-lenslet`: each lenslet of the array the map reaches, registered
/// on its own and figured on its own.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Lenslets {
    /// How a point is given to a lenslet and how each is registered.
    pub method: String,
    /// Lenslets in the array, and how many the map reaches (a point of
    /// it inside the lenslet's aperture).
    pub in_array: usize,
    pub reached: usize,
    /// Lenslets reached but not registered (a finding each, below).
    pub not_registered: usize,
    /// The registered lenslet with the largest error PV, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_pv: Option<usize>,
    pub each: Vec<LensletMeasured>,
}

/// One lenslet, measured.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletMeasured {
    /// Its index in its array, from 0: row by row from the least y, along
    /// each row from the least x (as the build report's lenslets).
    pub index: usize,
    /// Its row and column in the array, from 0: rows from the least y,
    /// columns along a row from the least x (`--lenslet ROW,COLUMN`).
    pub row: usize,
    pub column: usize,
    /// Its centre in the design (mm).
    pub centre_mm: [f64; 2],
    /// Map points inside its aperture widened by a fifth (valid or not),
    /// and the valid share.
    pub points_in_aperture: usize,
    pub valid_share: f64,
    /// Its registration: piston at its centre (µm), tilt (µrad), and its
    /// decentre (µm) in the measurement's frame against its place in the
    /// design; `from_array` the same less what the whole array's
    /// registration puts there (this lenslet's own error of place).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub registration: Option<LensletRegistration>,
    /// The error along the normal after its own registration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub form_error: Option<FormError>,
    /// Texture after its own form removal.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture: Option<Texture>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub texture_skipped: Option<String>,
    /// Why it was not registered: a coded finding (W0036), not an error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finding: Option<Finding>,
}

/// A lenslet's own placement.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LensletRegistration {
    pub piston_um: f64,
    pub tilt_x_urad: f64,
    pub tilt_y_urad: f64,
    pub decentre_x_um: f64,
    pub decentre_y_um: f64,
    /// The same, less what the whole array's registration gives there.
    pub from_array: FromArray,
    pub iterations: usize,
}

/// A lenslet's placement less the whole array's there.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct FromArray {
    pub piston_um: f64,
    pub tilt_x_urad: f64,
    pub tilt_y_urad: f64,
    pub decentre_x_um: f64,
    pub decentre_y_um: f64,
}

/// A coded finding about one lenslet.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Finding {
    pub code: String,
    pub message: String,
}

/// The file read.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Measurement {
    /// As given on the command line.
    pub file: String,
    /// `x3p`, `sdf`, `metropro_dat`, `metropro_ascii`, `xyz`, `profile`.
    pub format: String,
    /// `map`, `point_cloud` or `profile`.
    pub kind: String,
    /// The MD5 of the file's bytes (hex): which measurement this is.
    pub md5: String,
    /// The instrument or software the file names, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instrument: Option<String>,
    /// Points in the file, and how many are valid.
    pub points: usize,
    pub valid_points: usize,
    /// The pixel spacing along x and y (µm), for a map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pixel_um: Option<[f64; 2]>,
    /// Where the points lie, after centring (mm): [[x min, x max], [y min, y max]].
    pub extent_mm: [[f64; 2]; 2],
    /// Whether the map was centred on its middle pixel (false: the file's
    /// own coordinates, `--keep-origin`).
    pub centred: bool,
}

/// How much of the measured aperture is valid.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Coverage {
    /// Measured points inside the surface's aperture (valid or not).
    pub points_in_aperture: usize,
    /// The share of those that are valid, and the least share required.
    pub valid_share: f64,
    pub min_valid_share: f64,
}

/// The placement found.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Registration {
    pub method: String,
    pub piston_um: f64,
    /// Slopes of the fitted plane (µrad): +x and +y rise.
    pub tilt_x_urad: f64,
    pub tilt_y_urad: f64,
    /// Where the design's vertex sits in the measurement's frame (µm).
    pub decentre_x_um: f64,
    pub decentre_y_um: f64,
    /// The part turned about z against the design (µrad); absent for a
    /// surface of revolution.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clocking_urad: Option<f64>,
    /// Parameters not fitted, each with the reason.
    pub left_out: Vec<LeftOut>,
    pub iterations: usize,
}

#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct LeftOut {
    pub parameter: String,
    pub reason: String,
}

/// The error map's figures, as the acceptance section defines them:
/// measured − design along the surface normal, positive where material
/// is left; PV the largest less the least, RMS about the mean.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct FormError {
    pub along: String,
    pub points: usize,
    pub pv_nm: f64,
    pub rms_nm: f64,
    pub mean_nm: f64,
    /// The largest and least error (nm) and where (x, y, mm).
    pub max: Extreme,
    pub min: Extreme,
}

#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Extreme {
    pub nm: f64,
    pub at_mm: [f64; 2],
}

/// ISO 25178-2 parameters of the S-L surface.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct Texture {
    /// What was removed as form: the registered design surface.
    pub form_removed: String,
    /// The L-filter, named, and its nesting index λc (mm).
    pub filter: String,
    pub cutoff_mm: f64,
    pub sa_nm: f64,
    pub sq_nm: f64,
    pub sz_nm: f64,
    /// Root mean square gradient (dimensionless).
    pub sdq: f64,
    pub points: usize,
}

/// A turned part's set-up errors and the corrections to apply.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[schemars(deny_unknown_fields)]
pub struct SetUp {
    /// δx (µm): the tool stood this much further from the spindle axis
    /// than programmed (negative: it passed the centre).
    pub x_offset_um: f64,
    pub x_correction: String,
    /// |h| (µm): the tool tip's distance from the centre height (a map
    /// does not tell above from below): the stub found in rings `ring_um`
    /// wide, its edge placed between the points on either side of it.
    pub centre_height_um: f64,
    pub centre_height_correction: String,
    /// The radius of the uncut stub at the centre (µm; 0: none seen).
    pub stub_radius_um: f64,
    pub ring_um: f64,
    /// RMS of the ring-averaged error about the fitted cone (nm).
    pub cone_fit_rms_nm: f64,
    pub rings: usize,
    /// The model, in words.
    pub model: String,
}

/// The JSON Schema of [`MeasureReport`] as written (draft 2020-12).
pub fn schema() -> schemars::Schema {
    crate::json_schema::schema_of::<MeasureReport>()
}

/// The schema as committed at `docs/measure.schema.json`.
pub fn schema_text() -> String {
    crate::json_schema::schema_text_of::<MeasureReport>()
}

#[cfg(test)]
mod tests {
    /// The committed schema is the one the structs generate.
    #[test]
    fn committed_schema_is_current() {
        crate::json_schema::assert_schema_committed(
            "measure.schema.json",
            &super::schema_text(),
            "measure",
        );
    }
}
