//! 360° metadata in Matroska and WebM: the video track's `Projection` and `StereoMode`
//! elements. FFmpeg's Matroska muxer writes them from the video stream's side data
//! (`AV_PKT_DATA_SPHERICAL`, `AV_PKT_DATA_STEREO3D`: `mkv_write_video_projection`,
//! `mkv_write_stereo_mode` in `libavformat/matroskaenc.c`) and its demuxer reads them back
//! into it, so a Matroska file is stated at muxing, where an MP4 is tagged after
//! (`mirrorball-spherical`'s `tag`).
//!
//! What Matroska can state this way: the whole sphere equirectangular (`ProjectionType` 1,
//! the private data an `equi` box's payload with zero bounds), a cropped equirectangular
//! picture (VR180: the bounds as `equi` holds them) and the cube in `c3x2` (type 2,
//! `cbmp` layout 0); the stereo arrangement as `StereoMode` (1 side by side, left first;
//! 3 top-bottom, left first). FFmpeg's muxer writes no mesh (type 3), so v360's EAC goes
//! into Matroska without a projection: [`Mapping::Eac`] is not stateable here.

use ffmpeg::ffi::{
    av_stream_new_side_data, AVPacketSideDataType, AVStereo3D, AVStereo3DType, AVStereo3DView,
    AVStream,
};
use ffmpeg::format::stream::Stream;
use ffmpeg::packet::side_data::Type;
use ffmpeg_next as ffmpeg;
use mirrorball::spherical::v2::{Bounds, ProjectionData};
use mirrorball::spherical::Mapping;
use mirrorball::Error;
use mirrorball_core::Stereo;

/// libavutil's `AVSphericalMapping` (`spherical.h`, unchanged from FFmpeg 3.3 to 7.1; no
/// binding is generated for it): the projection, the pose in 16.16 degrees, the `equi`
/// bounds in 0.32 fixed point, the cube's padding.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
struct SphericalMapping {
    projection: u32,
    yaw: i32,
    pitch: i32,
    roll: i32,
    bound_left: u32,
    bound_top: u32,
    bound_right: u32,
    bound_bottom: u32,
    padding: u32,
}

/// `enum AVSphericalProjection`'s values.
const EQUIRECTANGULAR: u32 = 0;
const CUBEMAP: u32 = 1;
const EQUIRECTANGULAR_TILE: u32 = 2;

/// Whether a Matroska file can state `mapping` (see the module).
pub fn states(mapping: &Mapping) -> bool {
    !matches!(mapping, Mapping::Eac)
}

/// Gives the output video stream `st` the side data from which FFmpeg's Matroska muxer
/// writes `mapping` (for an eye of `eye` pixels) and `stereo`. Call before the header is
/// written.
///
/// # Safety
/// `st` must be a stream of an output context whose header is not yet written.
pub unsafe fn state(
    st: *mut AVStream,
    mapping: &Mapping,
    stereo: Stereo,
    eye: (u32, u32),
) -> Result<(), Error> {
    let data = mapping
        .projection_data(eye.0, eye.1)
        .map_err(|e| Error::request(e.to_string()))?;
    let m = match data {
        ProjectionData::Equirect(b) if b == Bounds::default() => SphericalMapping {
            projection: EQUIRECTANGULAR,
            ..Default::default()
        },
        ProjectionData::Equirect(b) => SphericalMapping {
            projection: EQUIRECTANGULAR_TILE,
            bound_left: b.left,
            bound_top: b.top,
            bound_right: b.right,
            bound_bottom: b.bottom,
            ..Default::default()
        },
        ProjectionData::Cubemap { padding, .. } => SphericalMapping {
            projection: CUBEMAP,
            padding,
            ..Default::default()
        },
        _ => {
            return Err(Error::request(format!(
                "Matroska's projection cannot state {mapping:?} through FFmpeg"
            )))
        }
    };
    let lost = || Error::system("FFmpeg could not keep the stream's side data (out of memory)");
    // SAFETY: the stream is the caller's; FFmpeg allocates the side data for its size, and
    // the write is unaligned-safe.
    let p = av_stream_new_side_data(
        st,
        AVPacketSideDataType::AV_PKT_DATA_SPHERICAL,
        std::mem::size_of::<SphericalMapping>(),
    );
    if p.is_null() {
        return Err(lost());
    }
    std::ptr::write_unaligned(p.cast::<SphericalMapping>(), m);
    let kind = match stereo {
        Stereo::Mono => return Ok(()),
        Stereo::SideBySide => AVStereo3DType::AV_STEREO3D_SIDEBYSIDE,
        Stereo::TopBottom => AVStereo3DType::AV_STEREO3D_TOPBOTTOM,
    };
    let p = av_stream_new_side_data(
        st,
        AVPacketSideDataType::AV_PKT_DATA_STEREO3D,
        std::mem::size_of::<AVStereo3D>(),
    );
    if p.is_null() {
        return Err(lost());
    }
    std::ptr::write_unaligned(
        p.cast::<AVStereo3D>(),
        AVStereo3D {
            type_: kind,
            flags: 0,
            view: AVStereo3DView::AV_STEREO3D_VIEW_PACKED,
        },
    );
    Ok(())
}

/// What a demuxed video stream's side data says (a Matroska file's `Projection` and
/// `StereoMode`, as FFmpeg's demuxer reads them) for an eye of `eye` pixels: the mapping
/// and the stereo arrangement, `None` where it states no projection, an error where it
/// states one mirrorball cannot read.
pub fn read(st: &Stream, eye: (u32, u32)) -> Option<Result<(Mapping, Stereo), Error>> {
    let mut spherical = None;
    let mut stereo = Stereo::Mono;
    for side in st.side_data() {
        match side.kind() {
            Type::DataSpherical if side.data().len() >= std::mem::size_of::<SphericalMapping>() => {
                // SAFETY: FFmpeg's demuxer wrote an AVSphericalMapping of this size.
                spherical = Some(unsafe {
                    std::ptr::read_unaligned(side.data().as_ptr().cast::<SphericalMapping>())
                });
            }
            Type::Stereo3d if side.data().len() >= std::mem::size_of::<AVStereo3D>() => {
                // SAFETY: as above, an AVStereo3D.
                let s =
                    unsafe { std::ptr::read_unaligned(side.data().as_ptr().cast::<AVStereo3D>()) };
                stereo = match s.type_ {
                    AVStereo3DType::AV_STEREO3D_SIDEBYSIDE => Stereo::SideBySide,
                    AVStereo3DType::AV_STEREO3D_TOPBOTTOM => Stereo::TopBottom,
                    _ => Stereo::Mono,
                };
            }
            _ => {}
        }
    }
    let m = spherical?;
    let (w, h) = match stereo {
        Stereo::Mono => eye,
        Stereo::SideBySide => (eye.0 / 2, eye.1),
        Stereo::TopBottom => (eye.0, eye.1 / 2),
    };
    let data = match m.projection {
        EQUIRECTANGULAR => ProjectionData::Equirect(Default::default()),
        EQUIRECTANGULAR_TILE => ProjectionData::Equirect(Bounds {
            top: m.bound_top,
            bottom: m.bound_bottom,
            left: m.bound_left,
            right: m.bound_right,
        }),
        CUBEMAP => ProjectionData::Cubemap {
            layout: 0,
            padding: m.padding,
        },
        other => {
            return Some(Err(Error::input(format!(
                "its projection (FFmpeg's spherical projection {other}) is not one mirrorball reads"
            ))))
        }
    };
    Some(
        Mapping::from_data(&data, w, h)
            .map(|mapping| (mapping, stereo))
            .map_err(|e| Error::input(e.to_string())),
    )
}
