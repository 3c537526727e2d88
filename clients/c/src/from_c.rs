//! The conversions from what a C caller passes to the Rust messages, written by hand: they
//! check the values (counts, finite numbers) and name the one that is wrong, which is no mirror
//! of the table. The C structs themselves are generated (`ctypes.rs`).

use flexdyn_proto::{EffectorInput, MAX_EFFECTOR_VALUES};

use crate::ctypes::FdEffectorInput;
use crate::error::{Code, Error};

/// The Rust input of one C `fd_effector_input`; its value count must be at most
/// [`MAX_EFFECTOR_VALUES`] and every value finite (the server rejects anything else).
pub fn effector_input(index: usize, c: &FdEffectorInput) -> Result<EffectorInput, Error> {
    let n = usize::try_from(c.n_values)
        .ok()
        .filter(|n| *n <= MAX_EFFECTOR_VALUES)
        .ok_or_else(|| {
            Error::new(
                Code::Argument,
                format!(
                    "inputs[{index}].n_values = {} exceeds {MAX_EFFECTOR_VALUES}",
                    c.n_values
                ),
            )
        })?;
    let values = &c.values[..n];
    if let Some(j) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::new(
            Code::Argument,
            format!("inputs[{index}].values[{j}] = {} is not finite", values[j]),
        ));
    }
    Ok(EffectorInput {
        effector_index: c.effector_index,
        values: values.to_vec(),
    })
}

/// Checks that a wrench is finite (`what` names it in the error).
pub fn finite3(what: &str, v: &[f64; 3]) -> Result<(), Error> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::new(
            Code::Argument,
            format!("{what}[{i}] = {} is not finite", v[i]),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_effector_inputs_are_named() {
        let mut c = FdEffectorInput {
            effector_index: 4,
            n_values: 33,
            ..FdEffectorInput::default()
        };
        let e = effector_input(2, &c).unwrap_err();
        assert_eq!(e.message, "inputs[2].n_values = 33 exceeds 32");
        c.n_values = 2;
        c.values[1] = f64::NAN;
        let e = effector_input(0, &c).unwrap_err();
        assert_eq!(e.message, "inputs[0].values[1] = NaN is not finite");
        c.values[1] = 0.25;
        let r = effector_input(0, &c).unwrap();
        assert_eq!((r.effector_index, r.values), (4, vec![0.0, 0.25]));
    }
}
