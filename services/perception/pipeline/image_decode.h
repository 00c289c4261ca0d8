#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_IMAGE_DECODE_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_IMAGE_DECODE_H_

#include "common/util/status.h"
#include "services/perception/pipeline/payloads.h"

namespace mbslam {

// Checks the geometry of a raw image against its byte count and the size limit,
// before anything is allocated from it: raw pixels need between
// row_stride * (height - 1) + width * channels and row_stride * height bytes; a
// compressed file's header must announce the message's width and height.
Status ValidateRawImage(const RawImage& raw, int max_dimension);

// Decodes raw pixels or a JPEG / PNG file into a gray image (and BGR when the source
// is colour and keep_color is set). A compressed image must decode to the size the
// message announced.
Status DecodeImage(const RawImage& raw, bool keep_color, ImageFrame* frame);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_IMAGE_DECODE_H_
