//! Families of coefficients named by a pattern (`A4`, `X2Y1`, `Z11`,
//! `Q3`) and the dimension each name stands for; and each family read from
//! a checked surface, once, as (power or index, value) pairs.

use super::{Check, Family, LENGTH, Param, Ty};
use crate::units::Dim;
use crate::value::{Field, Reader, Value};

/// `A1` … `A20`: the coefficient of |r|^j (or |u|^j for a cylinder), in mm^(1−j).
pub static POWER_COEFFICIENTS: Family = Family {
    describe: "coefficients `A1` … `A20` named by their power, in mm^(1-j)",
    param: |name| {
        let j: i8 = name.strip_prefix('A')?.parse().ok()?;
        (1..=20).contains(&j).then_some(Param {
            name: "A",
            ty: Ty::Quantity(power_dims(j)),
            required: false,
            check: Check::Any,
            doc: "coefficient of |r|^j, in mm^(1-j)",
        })
    },
};

/// `XiYj`: the coefficient of x^i y^j (i + j from 1 to 20), in mm^(1−i−j).
pub static XY_COEFFICIENTS: Family = Family {
    describe: "coefficients `XiYj` of x^i y^j (1 <= i + j <= 20), in mm^(1-i-j)",
    param: |name| {
        let (i, j) = xy_powers(name)?;
        Some(Param {
            name: "XiYj",
            ty: Ty::Quantity(power_dims((i + j) as i8)),
            required: false,
            check: Check::Any,
            doc: "coefficient of x^i y^j, in mm^(1-i-j)",
        })
    },
};

/// `Z1`, `Z2`, …: Zernike coefficients (lengths), in the surface's ordering.
pub static ZERNIKE_COEFFICIENTS: Family = Family {
    describe: "Zernike coefficients (lengths) numbered in the chosen `ordering`: `Z1` … `Z37` fringe, `Z0` … `Z230` ansi",
    param: |name| numbered_length(name, 'Z', 230, "Zj", "Zernike coefficient, a length"),
};

/// The highest order m of a Forbes coefficient `Qm`.
pub const FORBES_TOP: usize = 20;

/// `Q0` … `Q20`: Forbes Q-bfs coefficients (lengths).
pub static QBFS_COEFFICIENTS: Family = Family {
    describe: "Forbes Q-bfs coefficients `Q0` … `Q20` (lengths)",
    param: |name| {
        numbered_length(
            name,
            'Q',
            FORBES_TOP as u32,
            "Qm",
            "Q-bfs coefficient a_m, a length",
        )
    },
};

/// `Q0` … `Q20`: Forbes Q-con coefficients (lengths).
pub static QCON_COEFFICIENTS: Family = Family {
    describe: "Forbes Q-con coefficients `Q0` … `Q20` (lengths)",
    param: |name| {
        numbered_length(
            name,
            'Q',
            FORBES_TOP as u32,
            "Qm",
            "Q-con coefficient a_m, a length",
        )
    },
};

/// The `Aj` a surface states, by power j from 1 to 20, each looked up by
/// its name `A{j}`.
pub(super) fn power_terms(r: &Reader) -> Vec<(u32, f64)> {
    (1..=20u32)
        .filter_map(|j| r.num(&format!("A{j}")).map(|a| (j, a)))
        .collect()
}

/// The `Qm` of a Forbes surface, by order m from 0 to `FORBES_TOP`, each
/// looked up by its name `Q{m}`.
pub(super) fn forbes_terms(r: &Reader) -> Vec<(usize, f64)> {
    (0..=FORBES_TOP)
        .filter_map(|m| r.num(&format!("Q{m}")).map(|a| (m, a)))
        .collect()
}

/// The `XiYj` a surface states, as (i, j, value) in order of (i, j).
pub(super) fn xy_terms(fields: &[Field]) -> Vec<(u32, u32, f64)> {
    let mut terms: Vec<(u32, u32, f64)> = fields
        .iter()
        .filter_map(|fl| {
            let (i, j) = xy_powers(&fl.name)?;
            match fl.value {
                Value::Num(v, _) => Some((i, j, v)),
                _ => None,
            }
        })
        .collect();
    terms.sort_by_key(|t| (t.0, t.1));
    terms
}

/// The `Zj` a surface states, as (j, value) in order of j.
pub(super) fn zernike_terms(fields: &[Field]) -> Vec<(u32, f64)> {
    let mut terms: Vec<(u32, f64)> = fields
        .iter()
        .filter_map(|fl| {
            let j: u32 = fl.name.strip_prefix('Z')?.parse().ok()?;
            match fl.value {
                Value::Num(v, _) => Some((j, v)),
                _ => None,
            }
        })
        .collect();
    terms.sort_by_key(|t| t.0);
    terms
}

/// The parameter a name `<prefix>n` stands for, if n is at most `top`:
/// a coefficient that is a length.
fn numbered_length(
    name: &str,
    prefix: char,
    top: u32,
    pname: &'static str,
    doc: &'static str,
) -> Option<Param> {
    let n: u32 = name.strip_prefix(prefix)?.parse().ok()?;
    (n <= top).then_some(Param {
        name: pname,
        ty: LENGTH,
        required: false,
        check: Check::Any,
        doc,
    })
}

/// The (i, j) of a name `XiYj`, if it is one with 1 ≤ i + j ≤ 20.
pub fn xy_powers(name: &str) -> Option<(u32, u32)> {
    let rest = name.strip_prefix('X')?;
    let (i, j) = rest.split_once('Y')?;
    let (i, j): (u32, u32) = (i.parse().ok()?, j.parse().ok()?);
    (1..=20).contains(&(i + j)).then_some((i, j))
}

/// The dimension mm^(1−n) of a coefficient of a term of total power n,
/// as a static slice for `Ty::Quantity`.
fn power_dims(n: i8) -> &'static [Dim] {
    const fn d(n: i8) -> [Dim; 1] {
        [Dim::new(1 - n, 0, 0)]
    }
    static DIMS: [[Dim; 1]; 21] = [
        d(0),
        d(1),
        d(2),
        d(3),
        d(4),
        d(5),
        d(6),
        d(7),
        d(8),
        d(9),
        d(10),
        d(11),
        d(12),
        d(13),
        d(14),
        d(15),
        d(16),
        d(17),
        d(18),
        d(19),
        d(20),
    ];
    &DIMS[n.clamp(0, 20) as usize]
}
