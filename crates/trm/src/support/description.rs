//! Model descriptions read and written by the commands that bring a robot in.

use anyhow::Result;
use trm_kinematics::ModelDescription;
#[cfg(test)]
use trm_kinematics::srdf::Srdf;

/// The model description `model` was loaded with: the embedded one, the .ron file's, or none
/// (a plain URDF).
pub fn own_description(model: Option<&std::path::Path>) -> Result<ModelDescription> {
    let text = match model {
        None => trm_models::ICUB_UPPER_BODY_RON.to_string(),
        Some(p) if p.to_string_lossy() == "icub_upper_body" => {
            trm_models::ICUB_UPPER_BODY_RON.to_string()
        }
        Some(p) if p.to_string_lossy() == "icub_sagittal" => {
            trm_models::ICUB_SAGITTAL_RON.to_string()
        }
        Some(p) if p.extension().is_some_and(|e| e == "ron") => std::fs::read_to_string(p)?,
        Some(_) => return Ok(ModelDescription::default()),
    };
    let origin = model.map_or("icub_upper_body".into(), |p| p.display().to_string());
    Ok(ModelDescription::from_ron(&text, &origin)?)
}

/// Writes `description` to `out` with its `urdf` pointing at `model` (relative to `out`'s
/// directory when `model` lies in it).
pub fn write_description(
    description: &ModelDescription,
    model: Option<&std::path::Path>,
    out: &std::path::Path,
) -> Result<()> {
    let Some(urdf) = model.filter(|m| m.extension().is_some_and(|e| e == "urdf")) else {
        anyhow::bail!(
            "--write-description needs MODEL to be a .urdf file (the description names it)\n  fix: give the URDF as MODEL"
        );
    };
    let dir = out.parent().unwrap_or(std::path::Path::new(""));
    let absolute = |p: &std::path::Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (urdf_abs, dir_abs) = (absolute(urdf), absolute(dir));
    let mut d = description.clone();
    d.urdf = urdf_abs
        .strip_prefix(&dir_abs)
        .map(|p| p.to_path_buf())
        .unwrap_or(urdf_abs);
    let text = ron::ser::to_string_pretty(&d, ron::ser::PrettyConfig::new().compact_arrays(true))?;
    let text = format!(
        "// Written by `cargo xtask model-info {} --srdf … --write-description`.\n{text}\n",
        urdf.display()
    );
    crate::write_atomic(out, text.as_bytes())?;
    println!("wrote {}", out.display());
    Ok(())
}

/// Reads `srdf` into the model description of the URDF `model` (which has none) and writes it
/// to `out`: what `model-info MODEL --srdf SRDF --write-description OUT` does (for the
/// generated-files test).
#[cfg(test)]
pub fn write_srdf_description(
    model: &std::path::Path,
    srdf: &std::path::Path,
    out: &std::path::Path,
) -> Result<()> {
    let robot = crate::load_model(Some(model))?;
    let (description, _) =
        Srdf::load(srdf)?.to_description(&robot, &own_description(Some(model))?)?;
    write_description(&description, Some(model), out)
}
