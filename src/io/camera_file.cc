#include "auvdock/io/camera_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

#include <opencv2/core.hpp>

#include "auvdock/io/calibration.h"
#include "auvdock/io/input_error.h"

namespace auvdock {

namespace {

constexpr int kMaxMatrixSide = 16;

// Whether the file is an OpenCV FileStorage (YAML or XML), which must then be text: OpenCV
// 4.6's parser loops forever on a NUL byte (found by fuzzing).
bool IsOpenCvFileStorage(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  std::string first;
  std::getline(in, first);
  if (first.rfind("%YAML", 0) != 0 && first.rfind("<?xml", 0) != 0) return false;
  in.seekg(0);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const size_t nul = text.find('\0');
  if (nul != std::string::npos) {
    throw InputError(path + ": line " +
                     std::to_string(1 + std::count(text.begin(), text.begin() + nul, '\n')) +
                     ": a NUL byte: not a text file");
  }
  return true;
}

// OpenCV's messages span lines; the CLI prints one.
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& path, const std::string& key) {
  const cv::FileNode node = fs[key];
  if (node.empty()) throw InputError(path + ": key '" + key + "': missing");
  // A calibration's matrices are small. OpenCV allocates what rows and cols say before it reads
  // the data: a malformed size asked it for gigabytes (found by fuzzing).
  if (node.isMap()) {
    const cv::FileNode rows = node["rows"], cols = node["cols"];
    if (!rows.isInt() || !cols.isInt() || static_cast<int>(rows) < 1 ||
        static_cast<int>(rows) > kMaxMatrixSide || static_cast<int>(cols) < 1 ||
        static_cast<int>(cols) > kMaxMatrixSide) {
      throw InputError(path + ": key '" + key + "': rows and cols must be integers from 1 to " +
                       std::to_string(kMaxMatrixSide));
    }
  }
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    throw InputError(path + ": key '" + key + "': not a matrix");
  }
  if (m.empty()) throw InputError(path + ": key '" + key + "': empty matrix");
  m.convertTo(m, CV_64F);
  for (int i = 0; i < static_cast<int>(m.total()); ++i) {
    if (!std::isfinite(m.at<double>(i))) {
      throw InputError(path + ": key '" + key + "': not a finite number");
    }
  }
  return m;
}

int ReadPositiveInt(const cv::FileStorage& fs, const std::string& path, const std::string& key) {
  const cv::FileNode node = fs[key];
  if (node.empty() || !node.isInt()) {
    throw InputError(path + ": key '" + key + "': missing or not an integer");
  }
  const int v = static_cast<int>(node);
  if (v <= 0) throw InputError(path + ": key '" + key + "': must be positive");
  return v;
}

CameraCalibration ReadOpenCvCamera(const std::string& path) {
  cv::FileStorage fs;
  fs.open(path, cv::FileStorage::READ);
  if (!fs.isOpened()) throw InputError(path + ": cannot open OpenCV calibration file");
  const cv::Mat K = ReadMatrix(fs, path, "camera_matrix");
  if (K.rows != 3 || K.cols != 3 || !(K.at<double>(0, 0) > 0) || !(K.at<double>(1, 1) > 0)) {
    throw InputError(path + ": key 'camera_matrix': expected a 3x3 matrix with positive fx, fy");
  }
  const cv::Mat d = ReadMatrix(fs, path, "distortion_coefficients");
  if (d.total() != 4 && d.total() != 5) {
    throw InputError(path + ": key 'distortion_coefficients': expected 4 or 5 values "
                            "(k1 k2 p1 p2 [k3]); rational and thin-prism models are not supported");
  }
  std::array<double, 5> dist{};
  for (int i = 0; i < static_cast<int>(d.total()); ++i) dist[i] = d.at<double>(i);
  CameraCalibration cam;
  cam.name = "camera";
  cam.intrinsics = PinholeRadtanCamera(
      ReadPositiveInt(fs, path, "image_width"), ReadPositiveInt(fs, path, "image_height"),
      K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2), dist);
  return cam;
}

// OpenCV's parser reports malformed text by cv::Exception and, for some (found by fuzzing), by
// the standard library's exceptions (std::length_error from a string it sizes by the text).
CameraCalibration LoadOpenCvCamera(const std::string& path) {
  try {
    return ReadOpenCvCamera(path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": malformed OpenCV calibration file (" + OneLine(e.what()) + ")");
  }
}

}  // namespace

CameraCalibration LoadCameraCalibration(const std::string& path, const std::string& camera_name) {
  if (IsOpenCvFileStorage(path)) return LoadOpenCvCamera(path);
  const Calibration calibration = LoadCalibration(path);
  if (camera_name.empty()) {
    if (calibration.cameras.size() != 1) {
      throw InputError(path + ": holds " + std::to_string(calibration.cameras.size()) +
                       " cameras: choose one with --camera");
    }
    return calibration.cameras.front();
  }
  const CameraCalibration* cam = calibration.FindCamera(camera_name);
  if (cam == nullptr) throw InputError(path + ": no camera named '" + camera_name + "'");
  return *cam;
}

}  // namespace auvdock
