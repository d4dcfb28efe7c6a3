//! Tests of eenf-events's `aedat4/flatbuf` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::aedat4::flatbuf::*;

#[test]
fn builder_output_reads_back() {
    let mut b = Builder::new();
    let s = b.create_string("hello");
    let items: Vec<u8> = (0u8..32).collect();
    let v = b.create_struct_vector(&items, 2, 8);
    b.start_table();
    b.add_inline(1, &(-7i64).to_le_bytes(), 8);
    b.add_offset(2, s);
    b.add_offset(0, v);
    b.add_inline(3, &5i32.to_le_bytes(), 4);
    let t = b.end_table();
    let buf = b.finish_size_prefixed(t, b"TEST");
    let table = Table::size_prefixed_root(&buf, Some(b"TEST")).unwrap();
    assert_eq!(table.i64_field(1, 0).unwrap(), -7);
    assert_eq!(table.i32_field(3, 0).unwrap(), 5);
    assert_eq!(table.i32_field(9, 42).unwrap(), 42);
    assert_eq!(table.str_field(2).unwrap(), Some("hello"));
    let (n, bytes) = table.struct_vector(0, 16).unwrap().unwrap();
    assert_eq!(n, 2);
    assert_eq!(bytes, &items[..]);
    // the struct vector body is 8-aligned relative to the start of the whole buffer
    let start = bytes.as_ptr() as usize - buf.as_ptr() as usize;
    assert_eq!(start % 8, 0);
}

#[test]
fn corrupt_offsets_are_errors() {
    let buf = [0xffu8; 16];
    assert!(Table::root(&buf, None).is_err());
    assert!(Table::size_prefixed_root(&[1, 0], None).is_err());
}
