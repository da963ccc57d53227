//! Legacy VTK output of a packing (binary, opens in ParaView): every grain's surface as
//! triangles, with the grain id, its size D and its volume as cell data, so the real geometry
//! shows directly and can be coloured by size.

use std::io::Write;

use solver::dem::Bodies;

/// Subdivisions of the icosphere used for round shapes: 80 triangles per grain.
const SURFACE_LEVEL: usize = 1;

pub fn write_packing(out: &mut impl Write, bodies: &Bodies, sizes: &[f64], title: &str) -> std::io::Result<()> {
    let surfaces: Vec<_> = bodies.shape.iter().map(|s| s.surface(SURFACE_LEVEL)).collect();
    let points: usize = surfaces.iter().map(|(v, _)| v.len()).sum();
    let cells: usize = surfaces.iter().map(|(_, t)| t.len()).sum();
    // Legacy VTK binary data is big-endian.
    writeln!(out, "# vtk DataFile Version 3.0\n{title}\nBINARY\nDATASET POLYDATA")?;
    writeln!(out, "POINTS {points} float")?;
    for (k, (vertices, _)) in surfaces.iter().enumerate() {
        for v in vertices {
            let p = bodies.position[k] + bodies.orientation[k] * v;
            for c in [p.x, p.y, p.z] {
                out.write_all(&(c as f32).to_be_bytes())?;
            }
        }
    }
    writeln!(out, "\nPOLYGONS {cells} {}", 4 * cells)?;
    let mut offset = 0;
    for (vertices, triangles) in &surfaces {
        for t in triangles {
            for v in [3, offset + t[0] as i32, offset + t[1] as i32, offset + t[2] as i32] {
                out.write_all(&v.to_be_bytes())?;
            }
        }
        offset += vertices.len() as i32;
    }
    writeln!(out, "\nCELL_DATA {cells}")?;
    for name in ["grain", "D", "volume"] {
        writeln!(out, "SCALARS {name} float 1\nLOOKUP_TABLE default")?;
        for (k, (_, triangles)) in surfaces.iter().enumerate() {
            let value = match name {
                "grain" => k as f64,
                "D" => sizes[k],
                _ => bodies.volume[k],
            };
            let v = (value as f32).to_be_bytes();
            for _ in triangles {
                out.write_all(&v)?;
            }
        }
        writeln!(out)?;
    }
    Ok(())
}
