//! Tests of eenf-events's `aedat4` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::aedat4::*;
use eenf_events::Compression;

#[test]
fn parses_stream_list_from_dv_xml() {
    let xml = r#"<dv version="2.0"><node name="outInfo" path="/x/">
        <node name="0" path="/x/0/"><attr key="typeIdentifier" type="string">EVTS</attr>
          <node name="info" path="/x/0/info/"><attr key="sizeX" type="int">640</attr>
          <attr key="sizeY" type="int">480</attr><attr key="source" type="string">DVX</attr></node>
        </node>
        <node name="2" path="/x/2/"><attr key="typeIdentifier" type="string">IMUS</attr></node>
        </node></dv>"#;
    let s = parse_streams(xml);
    assert_eq!(s.len(), 2);
    assert_eq!((s[0].id, s[0].kind.as_str()), (0, "EVTS"));
    assert_eq!((s[0].width, s[0].height), (Some(640), Some(480)));
    assert_eq!(s[0].source.as_deref(), Some("DVX"));
    assert_eq!((s[1].id, s[1].kind.as_str()), (2, "IMUS"));
}

#[test]
fn compression_names_round_trip() {
    for code in 0..5 {
        let c = Compression::from_code(code).unwrap();
        assert_eq!(c.name().parse::<Compression>(), Ok(c));
        assert_eq!(c.code(), code);
    }
    assert_eq!("lz4-high".parse::<Compression>(), Ok(Compression::Lz4High));
    assert_eq!(Compression::from_code(7), None);
}
