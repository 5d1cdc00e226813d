//! Expedited SDO transfers (CiA-301 7.2.4.3), both sides.
//!
//! Every SDO frame has 8 data bytes: the command specifier `cs`, the index (little-endian),
//! the sub-index and four data bytes. The client (this master) sends requests on
//! 0x600 + node; the server (the drive) answers on 0x580 + node.
//!
//! | frame                                  | cs                        | data              |
//! |----------------------------------------|---------------------------|-------------------|
//! | download (write) request, 4/3/2/1 bytes | 0x23/0x27/0x2B/0x2F      | value, LE         |
//! | download response                      | 0x60                      | zero              |
//! | upload (read) request                  | 0x40                      | zero              |
//! | upload response, 4/3/2/1 bytes         | 0x43/0x47/0x4B/0x4F       | value, LE         |
//! | abort, either direction                | 0x80                      | abort code, LE    |
//!
//! In an expedited initiate frame, bit 1 (`e`) marks an expedited transfer, bit 0 (`s`) that
//! the size is indicated, and bits 2-3 (`n`) the number of bytes that do *not* hold data, so
//! the length is `4 - n`. `e = 1, s = 0` (0x22, 0x42) means four bytes of unspecified size;
//! the decoders accept it as four bytes. Segmented and block transfers are not implemented:
//! their command specifiers decode to [`DecodeError::SdoNotExpedited`] so that a drive
//! answering with one is reported, not misread. Bits marked "not used" in CiA-301 are ignored
//! on receipt and sent as zero.
//!
//! Matching a response to its request (same index and sub-index), the timeout and the
//! client-side abort on timeout belong to the transport layer, which holds the time.

use super::{check_len, cob, node_of, DecodeError, NodeId};
use crate::frame::CanFrame;

pub use super::abort::AbortCode;

/// A typed value to write with an expedited download.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdoValue {
    U8(u8),
    I8(i8),
    U16(u16),
    I16(i16),
    U32(u32),
    I32(i32),
}

impl SdoValue {
    /// The value's little-endian bytes.
    pub fn data(self) -> SdoData {
        let (bytes, len) = match self {
            Self::U8(v) => ([v, 0, 0, 0], 1),
            Self::I8(v) => ([v.to_le_bytes()[0], 0, 0, 0], 1),
            Self::U16(v) => widen(v.to_le_bytes()),
            Self::I16(v) => widen(v.to_le_bytes()),
            Self::U32(v) => (v.to_le_bytes(), 4),
            Self::I32(v) => (v.to_le_bytes(), 4),
        };
        SdoData { bytes, len }
    }
}

fn widen([a, b]: [u8; 2]) -> ([u8; 4], u8) {
    ([a, b, 0, 0], 2)
}

/// The 1..=4 data bytes of an expedited transfer, little-endian as on the wire.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct SdoData {
    bytes: [u8; 4],
    len: u8,
}

impl SdoData {
    /// `None` unless `data` has 1..=4 bytes.
    pub fn new(data: &[u8]) -> Option<Self> {
        let mut bytes = [0; 4];
        bytes.get_mut(..data.len())?.copy_from_slice(data);
        (!data.is_empty()).then_some(Self {
            bytes,
            len: data.len() as u8,
        })
    }

    pub fn as_bytes(&self) -> &[u8] {
        self.bytes
            .get(..usize::from(self.len))
            .unwrap_or(&self.bytes)
    }

    /// The bytes as a u8 if there is exactly one.
    pub fn to_u8(self) -> Option<u8> {
        (self.len == 1).then_some(self.bytes[0])
    }

    pub fn to_i8(self) -> Option<i8> {
        self.to_u8().map(|v| i8::from_le_bytes([v]))
    }

    /// The bytes as a u16 if there are exactly two.
    pub fn to_u16(self) -> Option<u16> {
        let [a, b, ..] = self.bytes;
        (self.len == 2).then_some(u16::from_le_bytes([a, b]))
    }

    pub fn to_i16(self) -> Option<i16> {
        self.to_u16().map(|v| v as i16)
    }

    /// The bytes as a u32 if there are exactly four.
    pub fn to_u32(self) -> Option<u32> {
        (self.len == 4).then_some(u32::from_le_bytes(self.bytes))
    }

    pub fn to_i32(self) -> Option<i32> {
        self.to_u32().map(|v| v as i32)
    }
}

impl From<SdoValue> for SdoData {
    fn from(value: SdoValue) -> Self {
        value.data()
    }
}

/// A server's answer to an expedited request, as decoded by the client.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdoResponse {
    DownloadAck {
        index: u16,
        sub: u8,
    },
    Uploaded {
        index: u16,
        sub: u8,
        data: SdoData,
    },
    Abort {
        index: u16,
        sub: u8,
        code: AbortCode,
    },
}

/// A client's request, as decoded by the server (the simulated drive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdoRequest {
    Download {
        index: u16,
        sub: u8,
        data: SdoData,
    },
    Upload {
        index: u16,
        sub: u8,
    },
    Abort {
        index: u16,
        sub: u8,
        code: AbortCode,
    },
}

const CS_DOWNLOAD_INIT: u8 = 1; // ccs of a download request
const CS_UPLOAD_INIT: u8 = 2; // ccs of an upload request, scs of an upload response
const CS_DOWNLOAD_ACK: u8 = 3; // scs of a download response
const CS_ABORT: u8 = 4;
const CS_BLOCK_UPLOAD: u8 = 5;
const CS_BLOCK_DOWNLOAD: u8 = 6;
const BIT_EXPEDITED: u8 = 0x02;
const BIT_SIZE: u8 = 0x01;

fn sdo_frame(id: u16, cs: u8, index: u16, sub: u8, payload: [u8; 4]) -> CanFrame {
    let [il, ih] = index.to_le_bytes();
    let [a, b, c, d] = payload;
    CanFrame::from_array(id, [cs, il, ih, sub, a, b, c, d])
}

/// An expedited initiate frame (download request or upload response) carrying `data`.
fn expedited(id: u16, ccs: u8, index: u16, sub: u8, data: SdoData) -> CanFrame {
    let n = 4 - data.len.clamp(1, 4);
    let cs = ccs << 5 | n << 2 | BIT_EXPEDITED | BIT_SIZE;
    sdo_frame(id, cs, index, sub, data.bytes)
}

/// The data of an expedited initiate frame, `None` if it is not expedited.
fn expedited_data(cs: u8, payload: [u8; 4]) -> Option<SdoData> {
    if cs & BIT_EXPEDITED == 0 {
        return None;
    }
    let len = if cs & BIT_SIZE != 0 {
        4 - (cs >> 2 & 0x3)
    } else {
        4
    };
    let mut bytes = [0; 4];
    for (i, (dst, src)) in bytes.iter_mut().zip(payload).enumerate() {
        *dst = if i < usize::from(len) { src } else { 0 };
    }
    Some(SdoData { bytes, len })
}

/// The fields of any SDO frame: `(cs, index, sub, payload)`.
fn fields(frame: &CanFrame) -> Result<(u8, u16, u8, [u8; 4]), DecodeError> {
    check_len(frame, 8, 8)?;
    let [cs, il, ih, sub, a, b, c, d] = frame.raw_data();
    Ok((cs, u16::from_le_bytes([il, ih]), sub, [a, b, c, d]))
}

// ---- client side ------------------------------------------------------------------------

/// Writes `value` to `index:sub` of `node`: `605#2B40600006000000` writes 0x0006 to 0x6040.
pub fn download_request(node: NodeId, index: u16, sub: u8, value: SdoValue) -> CanFrame {
    let id = node.cob_id(cob::SDO_RX);
    expedited(id, CS_DOWNLOAD_INIT, index, sub, value.data())
}

/// Reads `index:sub` of `node`: `605#4041600000000000` reads 0x6041.
pub fn upload_request(node: NodeId, index: u16, sub: u8) -> CanFrame {
    let id = node.cob_id(cob::SDO_RX);
    sdo_frame(id, CS_UPLOAD_INIT << 5, index, sub, [0; 4])
}

/// The client's abort of a transfer with `node` (after a timeout, for instance).
pub fn abort_request(node: NodeId, index: u16, sub: u8, code: AbortCode) -> CanFrame {
    let id = node.cob_id(cob::SDO_RX);
    sdo_frame(id, CS_ABORT << 5, index, sub, code.as_u32().to_le_bytes())
}

/// Decodes the answer of `node` to an expedited request.
pub fn decode_response(node: NodeId, frame: &CanFrame) -> Result<SdoResponse, DecodeError> {
    check_node(
        node,
        frame,
        cob::SDO_TX,
        "an SDO response from the addressed node",
    )?;
    let (cs, index, sub, payload) = fields(frame)?;
    match cs >> 5 {
        CS_DOWNLOAD_ACK => Ok(SdoResponse::DownloadAck { index, sub }),
        CS_UPLOAD_INIT => expedited_data(cs, payload)
            .map(|data| SdoResponse::Uploaded { index, sub, data })
            .ok_or(DecodeError::SdoNotExpedited { cs }),
        CS_ABORT => Ok(SdoResponse::Abort {
            index,
            sub,
            code: AbortCode::from_u32(u32::from_le_bytes(payload)),
        }),
        // Upload/download segment responses, block upload/download responses.
        0 | 1 | CS_BLOCK_UPLOAD | CS_BLOCK_DOWNLOAD => Err(DecodeError::SdoNotExpedited { cs }),
        _ => Err(DecodeError::SdoCommand { cs }),
    }
}

// ---- server side ------------------------------------------------------------------------

/// Decodes a request addressed to `node` (the simulated drive's own id).
pub fn decode_request(node: NodeId, frame: &CanFrame) -> Result<SdoRequest, DecodeError> {
    check_node(
        node,
        frame,
        cob::SDO_RX,
        "an SDO request to the addressed node",
    )?;
    let (cs, index, sub, payload) = fields(frame)?;
    match cs >> 5 {
        CS_DOWNLOAD_INIT => expedited_data(cs, payload)
            .map(|data| SdoRequest::Download { index, sub, data })
            .ok_or(DecodeError::SdoNotExpedited { cs }),
        CS_UPLOAD_INIT => Ok(SdoRequest::Upload { index, sub }),
        CS_ABORT => Ok(SdoRequest::Abort {
            index,
            sub,
            code: AbortCode::from_u32(u32::from_le_bytes(payload)),
        }),
        // Download segment, upload segment, block upload, block download requests.
        0 | 3 | CS_BLOCK_UPLOAD | CS_BLOCK_DOWNLOAD => Err(DecodeError::SdoNotExpedited { cs }),
        _ => Err(DecodeError::SdoCommand { cs }),
    }
}

/// The server's confirmation of a download: `585#6040600000000000`.
pub fn download_ack(node: NodeId, index: u16, sub: u8) -> CanFrame {
    let id = node.cob_id(cob::SDO_TX);
    sdo_frame(id, CS_DOWNLOAD_ACK << 5, index, sub, [0; 4])
}

/// The server's expedited answer to an upload: `585#4B41600037020000` returns 0x0237.
pub fn upload_response(node: NodeId, index: u16, sub: u8, data: SdoData) -> CanFrame {
    let id = node.cob_id(cob::SDO_TX);
    expedited(id, CS_UPLOAD_INIT, index, sub, data)
}

/// The server's abort: `585#8000200000000206` (object does not exist).
pub fn abort(node: NodeId, index: u16, sub: u8, code: AbortCode) -> CanFrame {
    let id = node.cob_id(cob::SDO_TX);
    sdo_frame(id, CS_ABORT << 5, index, sub, code.as_u32().to_le_bytes())
}

fn check_node(
    node: NodeId,
    frame: &CanFrame,
    base: u16,
    service: &'static str,
) -> Result<(), DecodeError> {
    match node_of(frame, base, service) {
        Ok(n) if n == node => Ok(()),
        _ => Err(DecodeError::CobId {
            id: frame.id(),
            service,
        }),
    }
}

#[cfg(test)]
mod tests;
