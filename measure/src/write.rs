//! Writing a height map as an ISO 25178-72 X3P archive: `main.xml`
//! (feature type SUR, x and y incremental in metres, z absolute float64,
//! no invalid-points array: an invalid point is NaN), `bindata/data.bin`
//! and `md5checksum.hex`, with the point data's MD5 in `main.xml`. What
//! the tests write to measure back (and, later, what a simulated cut is
//! handed over as); the reader does not share this code's layout
//! decisions, only the standard.

use std::io::Write;

use crate::map::HeightMap;

/// The archive's bytes. `instrument` goes into Record2's manufacturer.
pub fn x3p(m: &HeightMap, instrument: &str) -> Vec<u8> {
    let mut data = Vec::with_capacity(8 * m.z.len());
    for (z, v) in m.z.iter().zip(&m.valid) {
        let metres = if *v { z / 1000.0 } else { f64::NAN };
        data.extend(metres.to_le_bytes());
    }
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8" standalone="no" ?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">
  <Record1>
    <Revision>ISO5436 - 2000</Revision>
    <FeatureType>SUR</FeatureType>
    <Axes>
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx:e}</Increment><Offset>{x0:e}</Offset></CX>
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dy:e}</Increment><Offset>{y0:e}</Offset></CY>
      <CZ><AxisType>A</AxisType><DataType>D</DataType><Increment>1</Increment><Offset>0</Offset></CZ>
    </Axes>
  </Record1>
  <Record2>
    <Date>2026-01-01T00:00:00</Date>
    <Instrument><Manufacturer>{instrument}</Manufacturer><Model>lensc</Model><Serial>none</Serial><Version>{version}</Version></Instrument>
    <CalibrationDate>2026-01-01T00:00:00</CalibrationDate>
    <ProbingSystem><Type>Software</Type><Identification>lensc</Identification></ProbingSystem>
    <Comment/>
  </Record2>
  <Record3>
    <MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
    <DataLink><PointDataLink>bindata/data.bin</PointDataLink><MD5ChecksumPointData>{md5}</MD5ChecksumPointData></DataLink>
  </Record3>
  <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>
</p:ISO5436_2>
"#,
        dx = m.dx / 1000.0,
        dy = m.dy / 1000.0,
        x0 = m.x0 / 1000.0,
        y0 = m.y0 / 1000.0,
        nx = m.nx,
        ny = m.ny,
        md5 = crate::md5_hex(&data),
        version = env!("CARGO_PKG_VERSION"),
    );
    let mut out = std::io::Cursor::new(Vec::new());
    {
        let mut zip = zip::ZipWriter::new(&mut out);
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        let mut put = |name: &str, bytes: &[u8]| {
            zip.start_file(name, opts).expect("a zip entry in memory");
            zip.write_all(bytes).expect("written to memory");
        };
        put("main.xml", xml.as_bytes());
        put("bindata/data.bin", &data);
        put(
            "md5checksum.hex",
            format!("{} *main.xml\n", crate::md5_hex(xml.as_bytes())).as_bytes(),
        );
        zip.finish().expect("a zip archive in memory");
    }
    out.into_inner()
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_written_map_reads_back_bit_for_bit() {
        let z = vec![1e-3, f64::NAN, -2.5e-4, 7.0, 0.0, 1e-9];
        let mut m = crate::HeightMap::from_heights(3, 2, (0.002, 0.003), z);
        m.x0 = -0.002;
        let bytes = super::x3p(&m, "test");
        let back = crate::read::x3p::read(&bytes).expect("reads");
        assert_eq!(back.data, crate::Measured::Map(m));
    }
}
