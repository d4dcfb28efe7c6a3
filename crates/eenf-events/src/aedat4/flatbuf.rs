//! Just enough FlatBuffers for AEDAT4: a bounds-checked table reader and a small builder.
//!
//! Hand-written instead of generated code so that every offset read from a file is checked
//! against the buffer before use: a corrupt file yields an error, never a panic.

/// A table inside a FlatBuffer, addressed by its byte position.
#[derive(Clone, Copy)]
pub struct Table<'a> {
    buf: &'a [u8],
    pos: usize,
    vtable: usize,
    vtable_len: usize,
}

/// A FlatBuffer access outside the buffer, or an inconsistent offset.
#[derive(Debug)]
pub struct FbError(pub String);

type FbResult<T> = Result<T, FbError>;

fn read_u32(buf: &[u8], pos: usize) -> FbResult<u32> {
    buf.get(pos..pos + 4)
        .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
        .ok_or_else(|| {
            FbError(format!(
                "offset {pos} outside the {}-byte buffer",
                buf.len()
            ))
        })
}

fn read_u16(buf: &[u8], pos: usize) -> FbResult<u16> {
    buf.get(pos..pos + 2)
        .map(|b| u16::from_le_bytes(b.try_into().unwrap()))
        .ok_or_else(|| {
            FbError(format!(
                "offset {pos} outside the {}-byte buffer",
                buf.len()
            ))
        })
}

fn read_i64(buf: &[u8], pos: usize) -> FbResult<i64> {
    buf.get(pos..pos + 8)
        .map(|b| i64::from_le_bytes(b.try_into().unwrap()))
        .ok_or_else(|| {
            FbError(format!(
                "offset {pos} outside the {}-byte buffer",
                buf.len()
            ))
        })
}

impl<'a> Table<'a> {
    /// The root table of a buffer that is not size-prefixed; checks the 4-byte identifier
    /// when one is given.
    pub fn root(buf: &'a [u8], ident: Option<&[u8; 4]>) -> FbResult<Self> {
        if let Some(id) = ident {
            if buf.get(4..8) != Some(&id[..]) {
                return Err(FbError(format!(
                    "expected FlatBuffer identifier {:?}",
                    String::from_utf8_lossy(id)
                )));
            }
        }
        let root = read_u32(buf, 0)? as usize;
        Self::at(buf, root)
    }

    /// The root table of a size-prefixed buffer (u32 size, then the buffer).
    pub fn size_prefixed_root(buf: &'a [u8], ident: Option<&[u8; 4]>) -> FbResult<Self> {
        let size = read_u32(buf, 0)? as usize;
        if size > buf.len() - 4 {
            return Err(FbError(format!(
                "size prefix {size} larger than the {}-byte body",
                buf.len() - 4
            )));
        }
        Self::root(&buf[4..4 + size], ident)
    }

    fn at(buf: &'a [u8], pos: usize) -> FbResult<Self> {
        let soff = read_u32(buf, pos)? as i32 as i64;
        let vtable = pos as i64 - soff;
        if vtable < 0 || vtable as usize >= buf.len() {
            return Err(FbError(format!(
                "vtable of table at {pos} is outside the buffer"
            )));
        }
        let vtable = vtable as usize;
        let vtable_len = read_u16(buf, vtable)? as usize;
        if vtable_len < 4 || vtable + vtable_len > buf.len() {
            return Err(FbError(format!(
                "bad vtable length {vtable_len} at {vtable}"
            )));
        }
        Ok(Table {
            buf,
            pos,
            vtable,
            vtable_len,
        })
    }

    /// Byte position of field `index`, if present.
    fn field_pos(&self, index: usize) -> FbResult<Option<usize>> {
        let entry = 4 + 2 * index;
        if entry + 2 > self.vtable_len {
            return Ok(None);
        }
        let off = read_u16(self.buf, self.vtable + entry)? as usize;
        Ok(if off == 0 { None } else { Some(self.pos + off) })
    }

    /// A scalar i32 field, or `default`.
    pub fn i32_field(&self, index: usize, default: i32) -> FbResult<i32> {
        match self.field_pos(index)? {
            Some(p) => Ok(read_u32(self.buf, p)? as i32),
            None => Ok(default),
        }
    }

    /// A scalar i64 field, or `default`.
    pub fn i64_field(&self, index: usize, default: i64) -> FbResult<i64> {
        match self.field_pos(index)? {
            Some(p) => read_i64(self.buf, p),
            None => Ok(default),
        }
    }

    /// The raw bytes of an inline struct field of `size` bytes.
    pub fn struct_field(&self, index: usize, size: usize) -> FbResult<Option<&'a [u8]>> {
        match self.field_pos(index)? {
            Some(p) => self
                .buf
                .get(p..p + size)
                .map(Some)
                .ok_or_else(|| FbError(format!("struct field {index} outside the buffer"))),
            None => Ok(None),
        }
    }

    /// Position of the target of an offset field (vector, string or table).
    fn indirect(&self, index: usize) -> FbResult<Option<usize>> {
        match self.field_pos(index)? {
            Some(p) => {
                let off = read_u32(self.buf, p)? as usize;
                let target = p
                    .checked_add(off)
                    .filter(|&t| t < self.buf.len())
                    .ok_or_else(|| FbError(format!("field {index} points outside the buffer")))?;
                Ok(Some(target))
            }
            None => Ok(None),
        }
    }

    /// A vector of inline structs of `elem_size` bytes: (element count, the bytes of all elements).
    pub fn struct_vector(
        &self,
        index: usize,
        elem_size: usize,
    ) -> FbResult<Option<(usize, &'a [u8])>> {
        let Some(v) = self.indirect(index)? else {
            return Ok(None);
        };
        let n = read_u32(self.buf, v)? as usize;
        let bytes = n
            .checked_mul(elem_size)
            .and_then(|len| self.buf.get(v + 4..v + 4 + len))
            .ok_or_else(|| {
                FbError(format!(
                    "vector of {n} elements of {elem_size} bytes does not fit the buffer"
                ))
            })?;
        Ok(Some((n, bytes)))
    }

    /// A string field.
    pub fn str_field(&self, index: usize) -> FbResult<Option<&'a str>> {
        match self.struct_vector(index, 1)? {
            Some((_, bytes)) => std::str::from_utf8(bytes)
                .map(Some)
                .map_err(|_| FbError(format!("string field {index} is not UTF-8"))),
            None => Ok(None),
        }
    }

    /// A vector of tables.
    pub fn table_vector(&self, index: usize) -> FbResult<Vec<Table<'a>>> {
        let Some(v) = self.indirect(index)? else {
            return Ok(Vec::new());
        };
        let n = read_u32(self.buf, v)? as usize;
        if n > (self.buf.len() - v) / 4 {
            return Err(FbError(format!("table vector of {n} entries does not fit")));
        }
        (0..n)
            .map(|i| {
                let slot = v + 4 + 4 * i;
                let target = slot + read_u32(self.buf, slot)? as usize;
                Table::at(self.buf, target)
            })
            .collect()
    }
}

/// Builds a FlatBuffer back to front, as the format intends, for the few shapes AEDAT4 needs:
/// tables of scalars, offsets and inline structs, byte strings, struct vectors and table vectors.
pub struct Builder {
    /// Bytes written so far, stored reversed in position: `data[cap - len..]` is the buffer tail.
    buf: Vec<u8>,
    /// Fields of the table under construction: (field index, offset from end of the field value).
    fields: Vec<(usize, usize)>,
    table_start: usize,
    min_align: usize,
}

/// A position in the builder, counted from the end of the buffer.
#[derive(Clone, Copy)]
pub struct Offset(usize);

impl Default for Builder {
    fn default() -> Self {
        Self::new()
    }
}

impl Builder {
    /// An empty buffer.
    pub fn new() -> Self {
        Builder {
            buf: Vec::new(),
            fields: Vec::new(),
            table_start: 0,
            min_align: 1,
        }
    }

    /// Bytes written so far (the buffer grows towards the front, so this is the current offset).
    fn len(&self) -> usize {
        self.buf.len()
    }

    fn pad(&mut self, n: usize) {
        self.buf.extend(std::iter::repeat_n(0u8, n));
    }

    /// Pads so that after writing `extra` bytes the front is aligned to `align`.
    fn prep(&mut self, align: usize, extra: usize) {
        self.min_align = self.min_align.max(align);
        let pad = (align - ((self.len() + extra) % align)) % align;
        self.pad(pad);
    }

    /// Prepends raw bytes (given in natural order).
    fn prepend(&mut self, bytes: &[u8]) {
        self.buf.extend(bytes.iter().rev());
    }

    fn prepend_u32(&mut self, v: u32) {
        self.prep(4, 0);
        self.prepend(&v.to_le_bytes());
    }

    fn prepend_uoffset(&mut self, target: Offset) {
        self.prep(4, 0);
        let rel = (self.len() + 4 - target.0) as u32;
        self.prepend(&rel.to_le_bytes());
    }

    /// A vector of inline elements given as contiguous bytes (`n` elements of `align` alignment).
    pub fn create_struct_vector(&mut self, bytes: &[u8], n: usize, align: usize) -> Offset {
        self.prep(4.max(align), bytes.len());
        self.prep(4, bytes.len());
        self.prepend(bytes);
        self.prepend_u32(n as u32);
        Offset(self.len())
    }

    /// A string (NUL-terminated as the format requires).
    pub fn create_string(&mut self, s: &str) -> Offset {
        self.prep(4, s.len() + 1);
        self.prepend(&[0]);
        self.prepend(s.as_bytes());
        self.prepend_u32(s.len() as u32);
        Offset(self.len())
    }

    /// A vector of table offsets.
    pub fn create_offset_vector(&mut self, items: &[Offset]) -> Offset {
        self.prep(4, 4 * items.len());
        for it in items.iter().rev() {
            self.prepend_uoffset(*it);
        }
        self.prepend_u32(items.len() as u32);
        Offset(self.len())
    }

    /// Begins a table; its fields follow, then [`Builder::end_table`].
    pub fn start_table(&mut self) {
        self.fields.clear();
        self.table_start = self.len();
    }

    /// Adds a scalar or inline struct field (bytes in natural little-endian order).
    pub fn add_inline(&mut self, index: usize, bytes: &[u8], align: usize) {
        self.prep(align, bytes.len());
        self.prepend(bytes);
        self.fields.push((index, self.len()));
    }

    /// Adds an offset field.
    pub fn add_offset(&mut self, index: usize, target: Offset) {
        self.prepend_uoffset(target);
        self.fields.push((index, self.len()));
    }

    /// Finishes the table and writes its vtable in front of it.
    pub fn end_table(&mut self) -> Offset {
        // soffset placeholder, patched below
        self.prep(4, 0);
        self.prepend(&[0, 0, 0, 0]);
        let table = self.len();
        let nfields = self.fields.iter().map(|f| f.0 + 1).max().unwrap_or(0);
        let mut entries = vec![0u16; nfields];
        for &(idx, at) in &self.fields {
            entries[idx] = (table - at) as u16;
        }
        let vt_len = 4 + 2 * nfields;
        for e in entries.iter().rev() {
            self.prepend(&e.to_le_bytes());
        }
        self.prepend(&((table - self.table_start) as u16).to_le_bytes());
        self.prepend(&(vt_len as u16).to_le_bytes());
        let vtable = self.len();
        // soffset = table_pos - vtable_pos (in forward coordinates: vtable is before the table)
        let soff = (vtable - table) as i32;
        // the placeholder occupies reversed indices [table - 4, table), bytes in reverse order
        let mut b = soff.to_le_bytes();
        b.reverse();
        self.buf[table - 4..table].copy_from_slice(&b);
        self.fields.clear();
        Offset(table)
    }

    /// Finishes the buffer with `root`, a 4-byte identifier and a u32 size prefix, returning the
    /// bytes in forward order.
    pub fn finish_size_prefixed(mut self, root: Offset, ident: &[u8; 4]) -> Vec<u8> {
        let align = self.min_align.max(4);
        self.prep(align, 12);
        self.prepend(ident);
        self.prepend_uoffset(root);
        let size = self.len() as u32;
        self.prepend(&size.to_le_bytes());
        self.buf.reverse();
        self.buf
    }

    /// Finishes the buffer with `root` and a 4-byte identifier, without a size prefix.
    pub fn finish(mut self, root: Offset, ident: &[u8; 4]) -> Vec<u8> {
        let align = self.min_align.max(4);
        self.prep(align, 8);
        self.prepend(ident);
        self.prepend_uoffset(root);
        self.buf.reverse();
        self.buf
    }
}
