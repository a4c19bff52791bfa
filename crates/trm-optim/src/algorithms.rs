//! Every algorithm by name, with default settings: for command lines, spec files and tests.

use crate::core::{Optimizer, Start};
use crate::error::{Result, invalid};
use crate::{
    Cmaes, CmaesOptions, MetropolisHastings, MhOptions, NelderMead, OnePlusOne, OnePlusOneOptions,
    SimplexOptions, Sir, SirOptions, Snes, SnesOptions, Xnes, XnesOptions,
};

/// The names [`by_name`] accepts.
pub const ALGORITHMS: [&str; 8] = [
    "xnes",
    "snes",
    "cmaes",
    "oneplusone",
    "sir",
    "sird",
    "mh",
    "simplex",
];

/// The algorithm `name` with its default settings; `population` overrides λ (the number of
/// particles for SIR/SIRD; ignored by the single-point methods).
pub fn by_name(
    name: &str,
    start: &Start,
    population: Option<usize>,
) -> Result<Box<dyn Optimizer + Send>> {
    Ok(match name {
        "xnes" => Box::new(Xnes::new(
            start,
            &XnesOptions {
                population,
                ..Default::default()
            },
        )?),
        "snes" => Box::new(Snes::new(
            start,
            &SnesOptions {
                population,
                ..Default::default()
            },
        )?),
        "cmaes" => Box::new(Cmaes::new(
            start,
            &CmaesOptions {
                population,
                ..Default::default()
            },
        )?),
        "oneplusone" => Box::new(OnePlusOne::new(start, &OnePlusOneOptions::default())?),
        "sir" | "sird" => {
            let base = if name == "sir" {
                SirOptions::default()
            } else {
                SirOptions::direct()
            };
            Box::new(Sir::new(
                start,
                &SirOptions {
                    particles: population.unwrap_or(base.particles),
                    ..base
                },
            )?)
        }
        "mh" => Box::new(MetropolisHastings::new(start, &MhOptions::default())?),
        "simplex" => Box::new(NelderMead::new(start, &SimplexOptions::default())?),
        other => {
            return Err(invalid(
                "algorithm",
                format!("`{other}`; known: {}", ALGORITHMS.join(", ")),
            ));
        }
    })
}
