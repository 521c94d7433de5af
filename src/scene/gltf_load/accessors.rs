//! Reading accessors (dense and sparse) with checked offsets: the `gltf` crate's own readers
//! slice buffers unchecked.

/// An accessor without a buffer view is all zeros; refuse absurd counts rather than allocate them.
const MAX_VIEWLESS_COUNT: usize = 1 << 24;
/// One component as f32, normalised as glTF 2.0 §3.11 prescribes when `normalized`
/// (KHR_mesh_quantization allows integer positions).
pub(super) fn component_f32(
    data_type: gltf::accessor::DataType,
    normalized: bool,
    b: &[u8],
) -> Option<f32> {
    use gltf::accessor::DataType as T;
    Some(match (data_type, normalized) {
        (T::F32, _) => f32::from_le_bytes(b.try_into().ok()?),
        (T::I8, false) => i8::from_le_bytes(b.try_into().ok()?) as f32,
        (T::I8, true) => (i8::from_le_bytes(b.try_into().ok()?) as f32 / 127.0).max(-1.0),
        (T::U8, false) => u8::from_le_bytes(b.try_into().ok()?) as f32,
        (T::U8, true) => u8::from_le_bytes(b.try_into().ok()?) as f32 / 255.0,
        (T::I16, false) => i16::from_le_bytes(b.try_into().ok()?) as f32,
        (T::I16, true) => (i16::from_le_bytes(b.try_into().ok()?) as f32 / 32767.0).max(-1.0),
        (T::U16, false) => u16::from_le_bytes(b.try_into().ok()?) as f32,
        (T::U16, true) => u16::from_le_bytes(b.try_into().ok()?) as f32 / 65535.0,
        (T::U32, _) => u32::from_le_bytes(b.try_into().ok()?) as f32,
    })
}

/// One unsigned integer component (indices); `None` for other types or short data.
pub(super) fn component_u32(data_type: gltf::accessor::DataType, b: &[u8]) -> Option<u32> {
    use gltf::accessor::DataType as T;
    Some(match data_type {
        T::U8 => u8::from_le_bytes(b.try_into().ok()?) as u32,
        T::U16 => u16::from_le_bytes(b.try_into().ok()?) as u32,
        T::U32 => u32::from_le_bytes(b.try_into().ok()?),
        _ => return None,
    })
}

/// The bytes of a buffer view, checked to lie inside its loaded buffer.
pub(super) fn view_bytes<'b>(
    view: &gltf::buffer::View,
    buffers: &'b [Vec<u8>],
) -> Result<&'b [u8], String> {
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("buffer view #{} refers to a missing buffer", view.index()))?;
    view.offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "reads buffer view #{} (bytes {}..{}), which lies outside buffer #{} ({} bytes): \
                 accessor out of bounds; the file is corrupt or truncated",
                view.index(),
                view.offset(),
                view.offset().saturating_add(view.length()),
                view.buffer().index(),
                buffer.len()
            )
        })
}

/// Reads every element of an accessor (dense data, then sparse substitutions) with checked
/// offsets; `decode` turns one element's bytes into a value. Errors are phrases to prefix with
/// what was being read.
pub(super) fn read_accessor<T: Copy>(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
    zero: T,
    decode: impl Fn(&[u8]) -> Option<T>,
) -> Result<Vec<T>, String> {
    let index = accessor.index();
    let count = accessor.count();
    let mut values = match accessor.view() {
        Some(view) => read_dense(accessor, &view, buffers, &decode)?,
        None if count > MAX_VIEWLESS_COUNT => {
            return Err(format!(
                "accessor #{index} has no data but claims {count} elements; the file is corrupt"
            ))
        }
        None => vec![zero; count],
    };
    if let Some(sparse) = accessor.sparse() {
        substitute_sparse(accessor, &sparse, buffers, &decode, &mut values)?;
    }
    Ok(values)
}

/// The accessor's elements in its buffer view, each checked to lie inside it.
fn read_dense<T>(
    accessor: &gltf::Accessor,
    view: &gltf::buffer::View,
    buffers: &[Vec<u8>],
    decode: &impl Fn(&[u8]) -> Option<T>,
) -> Result<Vec<T>, String> {
    let index = accessor.index();
    let count = accessor.count();
    let element = accessor.size();
    let data = view_bytes(view, buffers)?;
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "accessor #{index}: byteStride {stride} of buffer view #{} is smaller than \
             one element ({element} bytes)",
            view.index()
        ));
    }
    let start = accessor.offset();
    if count > 0 {
        let needed = stride
            .checked_mul(count - 1)
            .and_then(|x| x.checked_add(start))
            .and_then(|x| x.checked_add(element));
        if needed.is_none_or(|n| n > data.len()) {
            return Err(format!(
                "accessor #{index} is out of bounds: {count} elements of {element} bytes \
                 (stride {stride}, offset {start}) do not fit in buffer view #{} \
                 ({} bytes); the file is corrupt or truncated",
                view.index(),
                data.len()
            ));
        }
    }
    let mut values = Vec::with_capacity(count);
    for i in 0..count {
        let at = start + i * stride;
        let bytes = data.get(at..at + element).ok_or_else(|| {
            format!("accessor #{index}: element {i} lies outside its buffer view")
        })?;
        values.push(
            decode(bytes)
                .ok_or_else(|| format!("accessor #{index}: element {i} cannot be decoded"))?,
        );
    }
    Ok(values)
}

/// Replaces the elements a sparse accessor names with its values, every offset checked.
fn substitute_sparse<T>(
    accessor: &gltf::Accessor,
    sparse: &gltf::accessor::sparse::Sparse,
    buffers: &[Vec<u8>],
    decode: &impl Fn(&[u8]) -> Option<T>,
    values: &mut [T],
) -> Result<(), String> {
    let index = accessor.index();
    let count = accessor.count();
    let element = accessor.size();
    let index_type = sparse.indices().index_type();
    let index_size = index_type.size();
    let index_data = view_bytes(&sparse.indices().view(), buffers)?;
    let value_data = view_bytes(&sparse.values().view(), buffers)?;
    let (index_start, value_start) = (sparse.indices().offset(), sparse.values().offset());
    for j in 0..sparse.count() {
        let out_of_bounds = || format!("accessor #{index}: sparse entry {j} is out of bounds");
        let ib = index_start
            .checked_add(j.checked_mul(index_size).ok_or_else(out_of_bounds)?)
            .and_then(|at| index_data.get(at..at.checked_add(index_size)?))
            .ok_or_else(out_of_bounds)?;
        let target = match index_type {
            gltf::accessor::sparse::IndexType::U8 => ib.first().map(|&b| b as usize),
            gltf::accessor::sparse::IndexType::U16 => {
                ib.try_into().ok().map(|b| u16::from_le_bytes(b) as usize)
            }
            gltf::accessor::sparse::IndexType::U32 => {
                ib.try_into().ok().map(|b| u32::from_le_bytes(b) as usize)
            }
        }
        .ok_or_else(out_of_bounds)?;
        let vb = value_start
            .checked_add(j.checked_mul(element).ok_or_else(out_of_bounds)?)
            .and_then(|at| value_data.get(at..at.checked_add(element)?))
            .ok_or_else(out_of_bounds)?;
        let value = decode(vb).ok_or_else(out_of_bounds)?;
        *values.get_mut(target).ok_or_else(|| {
            format!("accessor #{index}: sparse index {target} is out of range ({count} elements)")
        })? = value;
    }
    Ok(())
}
