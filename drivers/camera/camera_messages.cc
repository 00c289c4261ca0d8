#include "drivers/camera/camera_messages.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <vector>

#include "drivers/camera/image_codec.h"

namespace mbslam {
namespace {

void PutQuaternion(const Eigen::Quaterniond& q, double out[4]) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

void PutVector(const Eigen::Vector3d& v, double out[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

}  // namespace

Status EncodeFrameImage(const Frame& frame, const ImageOutputOptions& options,
                        mbslam::image_t* msg) {
  if (frame.image.empty()) return Status::Error("empty frame");
  if (frame.image.depth() != CV_8U ||
      (frame.image.channels() != 1 && frame.image.channels() != 3)) {
    return Status::Error("frames must be 8-bit gray or BGR");
  }
  cv::Mat image;
  bool color_changed = false;
  MBSLAM_RETURN_IF_ERROR(ApplyColorPolicy(frame.image, options.color, &image, &color_changed));
  msg->width = image.cols;
  msg->height = image.rows;

  const bool file_usable = options.encoding == "source" && !color_changed &&
                           !frame.file_bytes.empty() && frame.file_encoding >= 0;
  if (file_usable) {
    msg->encoding = frame.file_encoding;
    msg->row_stride = 0;
    msg->data.assign(frame.file_bytes.begin(), frame.file_bytes.end());
  } else if (options.encoding == "raw" || options.encoding == "source") {
    msg->encoding = image.channels() == 1 ? mbslam::image_t::ENCODING_GRAY8
                                          : mbslam::image_t::ENCODING_BGR8;
    const size_t row_bytes = static_cast<size_t>(image.cols) * image.elemSize();
    msg->row_stride = static_cast<int32_t>(row_bytes);
    msg->data.resize(row_bytes * static_cast<size_t>(image.rows));
    for (int r = 0; r < image.rows; ++r) {
      const uint8_t* src = image.ptr<uint8_t>(r);
      std::copy(src, src + row_bytes, msg->data.begin() + static_cast<ptrdiff_t>(row_bytes * r));
    }
  } else {
    std::vector<uint8_t> encoded;
    std::vector<int> params;
    const bool jpeg = options.encoding == "jpeg";
    if (jpeg) {
      params = {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality};
    } else {
      params = {cv::IMWRITE_PNG_COMPRESSION, options.png_compression};
    }
    try {
      if (!cv::imencode(jpeg ? ".jpg" : ".png", image, encoded, params)) {
        return Status::Error("image encoder failed");
      }
    } catch (const cv::Exception& e) {
      return Status::Error(std::string("image encoder failed: ") + e.what());
    }
    msg->encoding = jpeg ? mbslam::image_t::ENCODING_JPEG : mbslam::image_t::ENCODING_PNG;
    msg->row_stride = 0;
    msg->data = std::move(encoded);
  }
  msg->size = static_cast<int32_t>(msg->data.size());
  return Status::Ok();
}

Status DecodeImageMessage(const mbslam::image_t& msg, cv::Mat* image) {
  if (msg.size != static_cast<int32_t>(msg.data.size())) {
    return Status::Error("image_t: size field disagrees with the data");
  }
  if (msg.width <= 0 || msg.height <= 0) return Status::Error("image_t: bad width / height");
  switch (msg.encoding) {
    case mbslam::image_t::ENCODING_GRAY8:
    case mbslam::image_t::ENCODING_RGB8:
    case mbslam::image_t::ENCODING_BGR8: {
      const int channels = msg.encoding == mbslam::image_t::ENCODING_GRAY8 ? 1 : 3;
      const int64_t row_bytes = static_cast<int64_t>(msg.width) * channels;
      if (msg.row_stride < row_bytes ||
          static_cast<int64_t>(msg.row_stride) * msg.height > msg.size) {
        return Status::Error("image_t: data too small for width x height x stride");
      }
      cv::Mat view(msg.height, msg.width, channels == 1 ? CV_8UC1 : CV_8UC3,
                   const_cast<uint8_t*>(msg.data.data()), static_cast<size_t>(msg.row_stride));
      if (msg.encoding == mbslam::image_t::ENCODING_RGB8) {
        cv::cvtColor(view, *image, cv::COLOR_RGB2BGR);
      } else {
        *image = view.clone();
      }
      return Status::Ok();
    }
    case mbslam::image_t::ENCODING_JPEG:
    case mbslam::image_t::ENCODING_PNG: {
      const std::string bytes(msg.data.begin(), msg.data.end());
      ImageFileType type;
      bool unchanged = false;
      MBSLAM_RETURN_IF_ERROR(DecodeImageBytes(bytes, image, &type, &unchanged));
      if (image->cols != msg.width || image->rows != msg.height) {
        return Status::Error("image_t: compressed image size disagrees with width / height");
      }
      return Status::Ok();
    }
    default:
      return Status::Error("image_t: unknown encoding " + std::to_string(msg.encoding));
  }
}

void FillCalibrationMessage(const CameraIntrinsics& intrinsics, int64_t utime,
                            const std::string& camera_name, mbslam::camera_calibration_t* msg) {
  msg->utime = utime;
  msg->camera_name = camera_name;
  msg->width = intrinsics.width;
  msg->height = intrinsics.height;
  msg->fx = intrinsics.fx;
  msg->fy = intrinsics.fy;
  msg->cx = intrinsics.cx;
  msg->cy = intrinsics.cy;
  switch (intrinsics.model) {
    case DistortionModel::kNone:
      msg->distortion_model = mbslam::camera_calibration_t::DISTORTION_NONE;
      break;
    case DistortionModel::kRadTan:
      msg->distortion_model = mbslam::camera_calibration_t::DISTORTION_RADTAN;
      break;
    case DistortionModel::kFisheye:
      msg->distortion_model = mbslam::camera_calibration_t::DISTORTION_FISHEYE;
      break;
  }
  msg->distortion = intrinsics.model == DistortionModel::kNone ? std::vector<double>()
                                                                : intrinsics.distortion;
  msg->num_distortion = static_cast<int32_t>(msg->distortion.size());
}

void FillGroundTruthMessage(const Frame& frame, int64_t seq, mbslam::ground_truth_t* msg) {
  msg->utime = frame.utime;
  msg->frame_seq = seq;
  msg->source = frame.truth_source;
  msg->has_camera = frame.world_from_cam.has_value() ? 1 : 0;
  if (frame.world_from_cam) {
    PutVector(frame.world_from_cam->translation, msg->cam_position);
    PutQuaternion(frame.world_from_cam->rotation, msg->cam_orientation);
  } else {
    for (double& v : msg->cam_position) v = 0.0;
    msg->cam_orientation[0] = 1.0;
    msg->cam_orientation[1] = msg->cam_orientation[2] = msg->cam_orientation[3] = 0.0;
  }
  msg->bodies.clear();
  for (const BodyTruth& b : frame.bodies) {
    mbslam::body_state_t s{};
    s.id = b.id;
    s.name = b.name;
    PutVector(b.world_from_body.translation, s.position);
    PutQuaternion(b.world_from_body.rotation, s.orientation);
    PutVector(b.linear_velocity, s.linear_velocity);
    PutVector(b.angular_velocity, s.angular_velocity);
    PutVector(b.extent, s.extent);
    s.visible = b.visible ? 1 : 0;
    msg->bodies.push_back(s);
  }
  msg->num_bodies = static_cast<int32_t>(msg->bodies.size());
}

}  // namespace mbslam
