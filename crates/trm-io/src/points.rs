//! Point-cloud files: PLY (ASCII and binary, either byte order) and PCD (PCL's format: ASCII
//! and binary; `binary_compressed` is refused with the fix). Only the `x`, `y`, `z` of each point
//! are read; points with a non-finite coordinate (a depth camera's invalid pixels, as PCL
//! writes them in organised clouds) are dropped and counted.

use std::path::Path;

/// The points of a cloud file and how many non-finite ones were dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct PointFile {
    /// The finite points, in file order.
    pub points: Vec<[f64; 3]>,
    /// Points dropped for a non-finite coordinate.
    pub dropped: usize,
}

/// Reads a PLY or PCD file (by extension, else by its first line); the error says what is
/// wrong and where (the header line, or the point's index).
pub fn read_points(path: &Path) -> Result<PointFile, String> {
    let bytes = crate::read_input_bytes(path).map_err(|e| e.to_string())?;
    parse_points(&bytes, path)
}

/// [`read_points`] of a file's bytes; `path` gives the format and names the file in errors.
pub fn parse_points(bytes: &[u8], path: &Path) -> Result<PointFile, String> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let ply = match extension.as_deref() {
        Some("ply") => true,
        Some("pcd") => false,
        _ => bytes.starts_with(b"ply"),
    };
    let points = if ply {
        ply_points(bytes)?
    } else {
        pcd_points(bytes)?
    };
    let total = points.len();
    let points: Vec<[f64; 3]> = points
        .into_iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    if points.is_empty() {
        return Err(format!(
            "the file holds no finite point ({total} points in all)"
        ));
    }
    Ok(PointFile {
        dropped: total - points.len(),
        points,
    })
}

/// A numeric type of a binary field.
#[derive(Debug, Clone, Copy)]
enum Number {
    Int(usize),
    Unsigned(usize),
    Float(usize),
}

impl Number {
    fn size(self) -> usize {
        match self {
            Number::Int(n) | Number::Unsigned(n) | Number::Float(n) => n,
        }
    }

    fn read(self, b: &[u8], big: bool) -> f64 {
        macro_rules! get {
            ($t:ty) => {{
                let a = b.try_into().expect("sized");
                (if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }) as f64
            }};
        }
        match self {
            Number::Int(1) => get!(i8),
            Number::Int(2) => get!(i16),
            Number::Int(4) => get!(i32),
            Number::Int(_) => get!(i64),
            Number::Unsigned(1) => get!(u8),
            Number::Unsigned(2) => get!(u16),
            Number::Unsigned(4) => get!(u32),
            Number::Unsigned(_) => get!(u64),
            Number::Float(4) => get!(f32),
            Number::Float(_) => get!(f64),
        }
    }
}

/// Splits the header (lines up to and including the one starting with `end`) from the body.
fn header<'a>(bytes: &'a [u8], end: &str) -> Result<(Vec<&'a str>, &'a [u8]), String> {
    let mut lines = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let stop = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| at + p);
        let line = std::str::from_utf8(&bytes[at..stop])
            .map_err(|_| format!("header line {} is not text", lines.len() + 1))?
            .trim();
        lines.push(line);
        at = (stop + 1).min(bytes.len());
        if line.split_whitespace().next() == Some(end) {
            return Ok((lines, &bytes[at..]));
        }
        if lines.len() > 10_000 {
            break;
        }
    }
    Err(format!("the header never ends (no `{end}` line)"))
}

fn ply_points(bytes: &[u8]) -> Result<Vec<[f64; 3]>, String> {
    let (lines, body) = header(bytes, "end_header")?;
    if lines.first() != Some(&"ply") {
        return Err("line 1: a PLY file starts with `ply`".into());
    }
    let (mut format, mut vertices, mut properties) = (None, None, Vec::new());
    let mut in_vertex = false;
    let mut before = false;
    for (i, line) in lines.iter().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let bad = |what: &str| format!("header line {}: {what}: `{line}`", i + 1);
        match words.as_slice() {
            ["format", f, _] => format = Some(f.to_string()),
            ["element", "vertex", n] => {
                vertices = Some(n.parse::<usize>().map_err(|_| bad("a vertex count"))?);
                in_vertex = true;
            }
            ["element", ..] => {
                in_vertex = false;
                before |= vertices.is_none();
            }
            ["property", "list", ..] if in_vertex => {
                return Err(bad("vertices with list properties are not read"));
            }
            ["property", kind, name] if in_vertex => {
                let number = ply_number(kind).ok_or_else(|| bad("an unknown property type"))?;
                properties.push((name.to_string(), number));
            }
            _ => {}
        }
    }
    let count = vertices.ok_or("the header declares no `element vertex`")?;
    if before {
        return Err("the vertices are not the file's first element: write them first".into());
    }
    let column = |axis: &str| {
        properties
            .iter()
            .position(|(n, _)| n == axis)
            .ok_or_else(|| format!("the vertices have no `{axis}` property"))
    };
    let xyz = [column("x")?, column("y")?, column("z")?];
    match format.as_deref() {
        Some("ascii") => ascii_rows(body, xyz, count, "vertex", "vertices"),
        Some(f @ ("binary_little_endian" | "binary_big_endian")) => {
            let numbers: Vec<Number> = properties.iter().map(|p| p.1).collect();
            binary_rows(body, &numbers, xyz, count, f == "binary_big_endian")
        }
        other => Err(format!(
            "format {other:?} is not read: write ascii, binary_little_endian or binary_big_endian"
        )),
    }
}

fn ply_number(kind: &str) -> Option<Number> {
    Some(match kind {
        "char" | "int8" => Number::Int(1),
        "uchar" | "uint8" => Number::Unsigned(1),
        "short" | "int16" => Number::Int(2),
        "ushort" | "uint16" => Number::Unsigned(2),
        "int" | "int32" => Number::Int(4),
        "uint" | "uint32" => Number::Unsigned(4),
        "float" | "float32" => Number::Float(4),
        "double" | "float64" => Number::Float(8),
        _ => return None,
    })
}

/// `count` text rows of numbers, the coordinates at columns `xyz`; errors name the `row`
/// (vertex, point) and say when the file ends before the `count` of `rows` it declares.
fn ascii_rows(
    body: &[u8],
    xyz: [usize; 3],
    count: usize,
    row_name: &str,
    rows_name: &str,
) -> Result<Vec<[f64; 3]>, String> {
    let text = std::str::from_utf8(body).map_err(|_| "the ASCII body is not text")?;
    let mut rows = text.lines().filter(|l| !l.trim().is_empty());
    (0..count)
        .map(|k| {
            let row = rows.next().ok_or_else(|| {
                format!("{row_name} {k}: the file ends before its {count} {rows_name}")
            })?;
            let values: Vec<&str> = row.split_whitespace().collect();
            let value = |c: usize| {
                values
                    .get(c)
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or_else(|| format!("{row_name} {k}: `{row}` is not a row of numbers"))
            };
            Ok([value(xyz[0])?, value(xyz[1])?, value(xyz[2])?])
        })
        .collect()
}

/// `count` rows of fixed-size fields, the coordinates at field indices `xyz`.
fn binary_rows(
    body: &[u8],
    numbers: &[Number],
    xyz: [usize; 3],
    count: usize,
    big: bool,
) -> Result<Vec<[f64; 3]>, String> {
    let offsets: Vec<usize> = numbers
        .iter()
        .scan(0, |at, n| {
            let here = *at;
            *at += n.size();
            Some(here)
        })
        .collect();
    let stride: usize = numbers.iter().map(|n| n.size()).sum();
    if stride == 0
        || stride
            .checked_mul(count)
            .is_none_or(|need| body.len() < need)
    {
        return Err(format!(
            "the body holds {} bytes, short of the {count} points of {stride} bytes declared",
            body.len()
        ));
    }
    Ok(body
        .chunks_exact(stride)
        .take(count)
        .map(|row| {
            xyz.map(|c| numbers[c].read(&row[offsets[c]..offsets[c] + numbers[c].size()], big))
        })
        .collect())
}

fn pcd_points(bytes: &[u8]) -> Result<Vec<[f64; 3]>, String> {
    let (lines, body) = header(bytes, "DATA")?;
    let field = |key: &str| {
        lines
            .iter()
            .find(|l| l.split_whitespace().next() == Some(key))
            .map(|l| l.split_whitespace().skip(1).collect::<Vec<_>>())
    };
    let fields = field("FIELDS").ok_or("the header has no FIELDS line")?;
    let sizes = field("SIZE").ok_or("the header has no SIZE line")?;
    let types = field("TYPE").ok_or("the header has no TYPE line")?;
    let counts = field("COUNT").unwrap_or_else(|| vec!["1"; fields.len()]);
    let points = field("POINTS")
        .and_then(|p| p.first()?.parse::<usize>().ok())
        .ok_or("the header has no POINTS count")?;
    let data = field("DATA").and_then(|d| d.first().copied()).unwrap_or("");
    if [sizes.len(), types.len(), counts.len()] != [fields.len(); 3] {
        return Err("FIELDS, SIZE, TYPE and COUNT differ in length".into());
    }
    // every field expanded by its count, one number each
    let mut numbers = Vec::new();
    let mut first_of = Vec::new();
    for k in 0..fields.len() {
        let size: usize = sizes[k]
            .parse()
            .map_err(|_| format!("SIZE `{}`", sizes[k]))?;
        let number = match (types[k], size) {
            ("F", 4 | 8) => Number::Float(size),
            ("I", 1 | 2 | 4 | 8) => Number::Int(size),
            ("U", 1 | 2 | 4 | 8) => Number::Unsigned(size),
            _ => {
                return Err(format!(
                    "field `{}`: TYPE {} SIZE {size}",
                    fields[k], types[k]
                ));
            }
        };
        let count: usize = counts[k]
            .parse()
            .map_err(|_| format!("COUNT `{}`", counts[k]))?;
        if count == 0 || count > 4096 {
            return Err(format!(
                "field `{}`: COUNT {count}; give 1 to 4096 numbers per field",
                fields[k]
            ));
        }
        first_of.push(numbers.len());
        numbers.extend(std::iter::repeat_n(number, count));
    }
    let column = |axis: &str| {
        fields
            .iter()
            .position(|f| *f == axis)
            .map(|k| first_of[k])
            .ok_or_else(|| format!("FIELDS has no `{axis}`"))
    };
    let xyz = [column("x")?, column("y")?, column("z")?];
    match data {
        "ascii" => ascii_rows(body, xyz, points, "point", "POINTS"),
        "binary" => binary_rows(body, &numbers, xyz, points, false),
        "binary_compressed" => Err(
            "DATA binary_compressed is not read: save the cloud as binary or ascii (pcl_convert_pcd_ascii_binary)"
                .into(),
        ),
        other => Err(format!("DATA `{other}` is not read: write ascii or binary")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(name: &str, bytes: &[u8]) -> Result<PointFile, String> {
        parse_points(bytes, Path::new(name))
    }

    #[test]
    fn every_layout_reads_the_same_points() {
        let expected = vec![[1.0, 2.0, 3.0], [-0.5, 0.25, 4.0]];
        let ascii_ply = "ply\nformat ascii 1.0\ncomment by hand\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n1 2 3 255\n-0.5 0.25 4 0\n";
        assert_eq!(
            read("a.ply", ascii_ply.as_bytes()).unwrap().points,
            expected
        );
        for big in [false, true] {
            let order = if big { "big" } else { "little" };
            let mut bytes = format!("ply\nformat binary_{order}_endian 1.0\nelement vertex 2\nproperty double x\nproperty uchar intensity\nproperty float y\nproperty float z\nend_header\n").into_bytes();
            for p in &expected {
                let [x, y, z] = *p;
                let (xb, yb, zb) = if big {
                    (
                        x.to_be_bytes().to_vec(),
                        (y as f32).to_be_bytes(),
                        (z as f32).to_be_bytes(),
                    )
                } else {
                    (
                        x.to_le_bytes().to_vec(),
                        (y as f32).to_le_bytes(),
                        (z as f32).to_le_bytes(),
                    )
                };
                bytes.extend(xb);
                bytes.push(7);
                bytes.extend(yb);
                bytes.extend(zb);
            }
            assert_eq!(read("b.ply", &bytes).unwrap().points, expected, "{order}");
        }
        let ascii_pcd = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n1 2 3 0\nnan nan nan 0\n-0.5 0.25 4 0\n";
        let read_pcd = read("c.pcd", ascii_pcd.as_bytes()).unwrap();
        assert_eq!((read_pcd.points, read_pcd.dropped), (expected.clone(), 1));
        let mut binary = b"VERSION 0.7\nFIELDS normal x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 3 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n".to_vec();
        for p in &expected {
            binary.extend([0u8; 12]);
            for v in p {
                binary.extend((*v as f32).to_le_bytes());
            }
        }
        assert_eq!(read("d.pcd", &binary).unwrap().points, expected);
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let cases: [(&str, &[u8], &str); 12] = [
            ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n1 2\n", "no `z`"),
            ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n", "ends before its 3"),
            ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 1\n", "never ends"),
            ("a.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00", "short of the 9"),
            ("a.pcd", b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA binary_compressed\n", "pcl_convert_pcd_ascii_binary"),
            ("a.pcd", b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\nnan 1 2\n", "no finite point"),
            ("a.pcd", b"FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 1 2\n", "differ in length"),
            ("a.pcd", b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 0 0 0\nPOINTS 1\nDATA binary\n", "COUNT 0"),
            ("a.pcd", b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 18446744073709551615\nDATA binary\n\x00", "short of the"),
            ("a.ply", b"ply\nformat binary_big_endian 1.0\nelement vertex 9223372036854775807\nproperty double x\nproperty double y\nproperty double z\nend_header\n", "short of the"),
            ("a.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 inf 2\n", "no finite point"),
            ("a.ply", b"", "never ends"),
        ];
        for (name, bytes, says) in cases {
            let e = read(name, bytes).unwrap_err();
            assert!(e.contains(says), "{e}");
        }
    }
}
