//! [`FaultMonitor::storage_intact`]: each tag the monitor keeps, refused when invalid.

#![allow(clippy::unwrap_used)]
use super::*;
use crate::foundation::stored::{accepts, refuses};
use crate::{team::presets, FaultDetection};
use core::ptr::addr_of_mut;

#[test]
fn an_invalid_response_report_or_masking_tag_is_refused() {
    let settings = ControllerSettings {
        fault_detection: Some(FaultDetection::recommended(FaultResponse::Mask)),
        ..ControllerSettings::offset_free_law()
    };
    let team = presets::a4_inc::<f32, 4>().unwrap();
    let mut m = FaultMonitor::<f32, 4>::new(&settings, &team, 27.0)
        .unwrap()
        .get()
        .unwrap();
    let check = FaultMonitor::<f32, 4>::storage_intact;
    m.masked = Stored::Present(Masked {
        agent: 1,
        refused: true,
    });
    let flag = m
        .masked
        .as_ref()
        .map(|k| &k.refused as *const bool as usize)
        .unwrap();
    let refused = flag - &m as *const _ as usize;
    assert!(accepts(&m, check));
    type P = *mut FaultMonitor<f32, 4>;
    assert!(refuses(
        &m,
        2,
        |p: P| unsafe { addr_of_mut!((*p).response).cast() },
        check
    ));
    assert!(refuses(
        &m,
        2,
        |p: P| unsafe { addr_of_mut!((*p).reported).cast() },
        check
    ));
    assert!(refuses(
        &m,
        2,
        |p: P| unsafe { addr_of_mut!((*p).masked).cast() },
        check
    ));
    assert!(refuses(
        &m,
        2,
        |p: P| unsafe { p.cast::<u8>().add(refused) },
        check
    ));
    assert!(refuses(
        &m,
        2,
        |p: P| unsafe { addr_of_mut!((*p).state).cast() },
        check
    ));
}
