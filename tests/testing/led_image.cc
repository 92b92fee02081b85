#include "tests/testing/led_image.h"

#include <algorithm>
#include <cmath>

namespace auvdock::test {

void AddLed(const Led& led, cv::Mat* image) {
  const int r = static_cast<int>(std::ceil(4 * led.halo_px + led.core_px));
  const int x0 = std::max(0, static_cast<int>(led.uv.x()) - r);
  const int x1 = std::min(image->cols, static_cast<int>(led.uv.x()) + r);
  const int y0 = std::max(0, static_cast<int>(led.uv.y()) - r);
  const int y1 = std::min(image->rows, static_cast<int>(led.uv.y()) + r);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      double core = 0.0;
      for (int sy = 0; sy < 4; ++sy) {
        for (int sx = 0; sx < 4; ++sx) {
          const double dx = x - 0.375 + 0.25 * sx - led.uv.x();
          const double dy = y - 0.375 + 0.25 * sy - led.uv.y();
          core += (dx * dx + dy * dy <= led.core_px * led.core_px) / 16.0;
        }
      }
      const double d2 = (x - led.uv.x()) * (x - led.uv.x()) + (y - led.uv.y()) * (y - led.uv.y());
      const double halo = std::exp(-0.5 * d2 / (led.halo_px * led.halo_px));
      cv::Vec3f& p = image->at<cv::Vec3f>(y, x);
      p += cv::Vec3f(320.0f, 170.0f, 50.0f) * static_cast<float>(halo) +
           cv::Vec3f(400.0f, 400.0f, 400.0f) * static_cast<float>(core);
    }
  }
}

}  // namespace auvdock::test
