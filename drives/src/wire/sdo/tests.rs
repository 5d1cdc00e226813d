//! Candump vectors for both sides of the expedited SDO codec, malformed frames included.

use super::*;
use crate::wire::frame;

const N5: NodeId = match NodeId::new(5) {
    Some(n) => n,
    None => unreachable!(),
};

#[test]
fn download_requests_and_acks() {
    let cases = [
        (0x6060, 0, SdoValue::I8(8), "605#2F60600008000000"),
        (0x6040, 0, SdoValue::U16(0x0006), "605#2B40600006000000"),
        (0x1017, 0, SdoValue::U16(100), "605#2B17100064000000"),
        (0x60C2, 2, SdoValue::I8(-3), "605#2FC26002FD000000"),
        (0x607A, 0, SdoValue::I32(-2), "605#237A6000FEFFFFFF"),
        (
            0x1016,
            1,
            SdoValue::U32(0x0001_0064),
            "605#2316100164000100",
        ),
        (
            0x1600,
            1,
            SdoValue::U32(0x6040_0010),
            "605#2300160110004060",
        ),
        (0x6065, 0, SdoValue::I16(-1), "605#2B656000FFFF0000"),
        (0x6061, 0, SdoValue::U8(0xFF), "605#2F616000FF000000"),
    ];
    for (index, sub, value, s) in cases {
        let f = download_request(N5, index, sub, value);
        assert_eq!(f.to_string(), s);
        let data = value.data();
        let req = SdoRequest::Download { index, sub, data };
        assert_eq!(decode_request(N5, &f), Ok(req), "{s}");
        let ack = download_ack(N5, index, sub);
        assert_eq!(
            decode_response(N5, &ack),
            Ok(SdoResponse::DownloadAck { index, sub })
        );
    }
    assert_eq!(
        download_ack(N5, 0x6040, 0).to_string(),
        "585#6040600000000000"
    );
}

#[test]
fn uploads() {
    assert_eq!(
        upload_request(N5, 0x6041, 0).to_string(),
        "605#4041600000000000"
    );
    let up = SdoRequest::Upload {
        index: 0x6041,
        sub: 0,
    };
    assert_eq!(decode_request(N5, &frame("605#4041600000000000")), Ok(up));
    let cases: [(&[u8], &str); 4] = [
        (&[0x37, 0x02], "585#4B41600037020000"),
        (&[0x08], "585#4F61600008000000"),
        (&[1, 2, 3], "585#4741600001020300"),
        (&[0xFE, 0xFF, 0xFF, 0xFF], "585#43646000FEFFFFFF"),
    ];
    for (bytes, s) in cases {
        let f = frame(s);
        let [_, il, ih, sub, ..] = f.raw_data();
        let (index, data) = (u16::from_le_bytes([il, ih]), SdoData::new(bytes).unwrap());
        assert_eq!(upload_response(N5, index, sub, data), f);
        let resp = decode_response(N5, &f);
        assert_eq!(resp, Ok(SdoResponse::Uploaded { index, sub, data }), "{s}");
    }
    // Expedited without size indicated: four bytes.
    let Ok(SdoResponse::Uploaded { data, .. }) =
        decode_response(N5, &frame("585#4241600037020000"))
    else {
        panic!("0x42 is an expedited upload response");
    };
    assert_eq!(data.to_u32(), Some(0x0237));
    // Bytes past the indicated size are not data.
    let r = decode_response(N5, &frame("585#4B41600037021122"));
    let data = SdoData::new(&[0x37, 0x02]).unwrap();
    let expected = SdoResponse::Uploaded {
        index: 0x6041,
        sub: 0,
        data,
    };
    assert_eq!(r, Ok(expected));
}

#[test]
fn typed_views_of_data() {
    let d = SdoValue::I32(-2).data();
    assert_eq!(
        (d.to_i32(), d.to_u32(), d.to_u16()),
        (Some(-2), Some(u32::MAX - 1), None)
    );
    let d = SdoValue::I16(-300).data();
    assert_eq!(
        (d.to_i16(), d.to_u8(), d.as_bytes()),
        (Some(-300), None, &[0xD4, 0xFE][..])
    );
    assert_eq!(SdoValue::I8(-3).data().to_i8(), Some(-3));
    assert_eq!(SdoData::new(&[]), None);
    assert_eq!(SdoData::new(&[0; 5]), None);
}

#[test]
fn aborts_in_both_directions() {
    let code = AbortCode::ObjectDoesNotExist;
    let f = abort(N5, 0x2000, 0, code);
    assert_eq!(f.to_string(), "585#8000200000000206");
    let expected = SdoResponse::Abort {
        index: 0x2000,
        sub: 0,
        code,
    };
    assert_eq!(decode_response(N5, &f), Ok(expected));
    let f = abort_request(N5, 0x6064, 0, AbortCode::TimedOut);
    assert_eq!(f.to_string(), "605#8064600000000405");
    let expected = SdoRequest::Abort {
        index: 0x6064,
        sub: 0,
        code: AbortCode::TimedOut,
    };
    assert_eq!(decode_request(N5, &f), Ok(expected));
    let r = decode_response(N5, &frame("585#8000200078563412"));
    let code = AbortCode::Other(0x1234_5678);
    assert_eq!(
        r,
        Ok(SdoResponse::Abort {
            index: 0x2000,
            sub: 0,
            code
        })
    );
}

/// Builders for the expected errors, so that the tables stay one line per vector.
fn cob(service: &'static str) -> impl Fn(u16) -> DecodeError {
    move |id| DecodeError::CobId { id, service }
}

fn len(id: u16, len: u8) -> DecodeError {
    DecodeError::Length {
        id,
        len,
        min: 8,
        max: 8,
    }
}

fn not_expedited(cs: u8) -> DecodeError {
    DecodeError::SdoNotExpedited { cs }
}

#[test]
fn rejects_malformed_responses() {
    let cob = cob("an SDO response from the addressed node");
    let cases = [
        ("586#6040600000000000", cob(0x586)),
        ("605#6040600000000000", cob(0x605)),
        ("580#6040600000000000", cob(0x580)),
        ("585#60406000", len(0x585, 4)),
        ("585#", len(0x585, 0)),
        ("585#4141600004000000", not_expedited(0x41)),
        ("585#0000000000000000", not_expedited(0x00)),
        ("585#2000000000000000", not_expedited(0x20)),
        ("585#A400000000000000", not_expedited(0xA4)),
        ("585#E040600000000000", DecodeError::SdoCommand { cs: 0xE0 }),
    ];
    for (s, e) in cases {
        assert_eq!(decode_response(N5, &frame(s)), Err(e), "{s}");
    }
}

#[test]
fn rejects_malformed_requests() {
    let cob = cob("an SDO request to the addressed node");
    let cases = [
        ("606#4041600000000000", cob(0x606)),
        ("585#4041600000000000", cob(0x585)),
        ("605#40416000000000", len(0x605, 7)),
        ("605#2140600004000000", not_expedited(0x21)),
        ("605#6000000000000000", not_expedited(0x60)),
        ("605#C600000000000000", not_expedited(0xC6)),
        ("605#E040600000000000", DecodeError::SdoCommand { cs: 0xE0 }),
    ];
    for (s, e) in cases {
        assert_eq!(decode_request(N5, &frame(s)), Err(e), "{s}");
    }
}
