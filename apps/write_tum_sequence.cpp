// Writes a synthetic dynamic RGB-D sequence (dyncull::sim::Scene) in TUM RGB-D format, so any SLAM
// system can run on it: rgb/*.png, depth/*.png (16-bit, 5000 per metre), rgb.txt, depth.txt,
// associations.txt, groundtruth.txt (timestamp tx ty tz qx qy qz qw of world_from_cam), camera.txt
// ("key value" lines: fx fy cx cy width height depth_units_per_metre, as dynamic_vo --dataset reads it),
// detections/*.txt (YOLO style "class cx cy w h conf", normalised; one per rgb image, same stem) indexed
// by detections.txt, the same boxes in pixels as detections_json/NNNNNN.json (eval/yolo_json.hpp's
// schema, timestamp = the rgb stamp), and the truth masks instance/*.png (16-bit ids) and moving/*.png
// (255 = moving surface).
//
// Usage: write_tum_sequence OUTDIR [--family NAME] [--motion static|xyz|rpy|halfsphere] [--frames N]
//                                  [--seed S] [--clean-depth]
#include "dyncull/core/pixel.hpp"
#include "dyncull/sim/families.hpp"
#include "dyncull/sim/scene.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

int usage(const char* why) {
  std::cerr << "write_tum_sequence: " << why << "\n"
            << "usage: write_tum_sequence OUTDIR [--family NAME] [--motion static|xyz|rpy|halfsphere] [--frames N] "
               "[--seed S] [--clean-depth]\n"
            << "families (default walking):\n"
            << dyncull::sim::format_scene_families();
  return 2;
}

bool parse_motion(const std::string& s, dyncull::sim::CameraMotion* m) {
  using dyncull::sim::CameraMotion;
  for (CameraMotion c : {CameraMotion::Static, CameraMotion::Xyz, CameraMotion::Rpy, CameraMotion::Halfsphere}) {
    if (s == dyncull::sim::to_string(c)) {
      *m = c;
      return true;
    }
  }
  return false;
}

bool parse_int(const std::string& s, long long lo, long long hi, long long* out) {
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (end == s.c_str() || *end != '\0' || v < lo || v > hi) return false;
  *out = v;
  return true;
}

std::string stamp(double t) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(6) << t;
  return os.str();
}

// One frame's boxes as eval/yolo_json.hpp reads them: bbox [x0, y0, x1, y1] in pixels.
bool write_json_detections(const std::filesystem::path& path, int index, const std::string& ts,
                           const std::string& rgb_name, const dyncull::sim::FrameData& f) {
  std::ofstream out(path);
  out << "{\"frame_id\": " << index << ", \"timestamp\": " << ts << ", \"image_path\": \"" << rgb_name
      << "\", \"detections\": [";
  out << std::setprecision(6);
  for (std::size_t k = 0; k < f.detections.size(); ++k) {
    const auto& d = f.detections[k];
    out << (k ? ", " : "") << "{\"class_id\": " << d.class_id << ", \"confidence\": " << d.confidence
        << ", \"bbox\": [" << d.box.x0 << ", " << d.box.y0 << ", " << d.box.x1 << ", " << d.box.y1 << "]}";
  }
  out << "]}\n";
  return static_cast<bool>(out);
}

/// The scene of the command line: the family's (default walking), then --motion, --frames, --seed and
/// --clean-depth in any order on top of it. False, with why, for a bad or unknown argument.
bool parse_scene_options(int argc, char** argv, dyncull::sim::SceneOptions* options, std::string* family,
                         std::string* why) {
  using namespace dyncull::sim;
  *family = "walking";
  for (int k = 2; k + 1 < argc; ++k)
    if (std::string(argv[k]) == "--family") *family = argv[k + 1];
  SceneFamily chosen;
  if (!find_scene_family(*family, &chosen, why)) return false;
  *options = chosen.options;
  auto bad = [why](std::string reason) {
    *why = std::move(reason);
    return false;
  };
  for (int k = 2; k < argc; ++k) {
    const std::string arg = argv[k];
    const bool has_value = k + 1 < argc;
    long long value = 0;
    if (arg == "--family" && has_value) {
      ++k;  // read above
    } else if (arg == "--motion" && has_value) {
      if (!parse_motion(argv[++k], &options->motion)) return bad("unknown motion");
    } else if (arg == "--frames" && has_value) {
      if (!parse_int(argv[++k], 1, 1000000, &value)) return bad("--frames needs a positive integer");
      options->num_frames = static_cast<int>(value);
    } else if (arg == "--seed" && has_value) {
      if (!parse_int(argv[++k], 0, 0x7FFFFFFFFFFFFFFFll, &value))
        return bad("--seed needs a non-negative integer");
      options->seed = static_cast<std::uint64_t>(value);
    } else if (arg == "--clean-depth") {
      options->depth_noise = false;
    } else {
      return bad("unknown or incomplete argument " + arg);
    }
  }
  return true;
}

// The TUM depth image (16-bit, 5000 per metre) and the moving mask (255 = moving) of a frame.
void depth_and_moving_images(const dyncull::sim::FrameData& f, cv::Mat* depth16, cv::Mat* moving8) {
  for (int v = 0; v < f.height; ++v) {
    auto* drow = depth16->ptr<std::uint16_t>(v);
    auto* mrow = moving8->ptr<std::uint8_t>(v);
    for (int u = 0; u < f.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(f.width) + static_cast<std::size_t>(u);
      const double units = std::round(static_cast<double>(f.depth_m[i]) * 5000.0);
      int raw = 0;  // beyond 13.1 m, negative or NaN: no measurement
      drow[u] = dyncull::checked_int(units, 0, 65535, &raw) ? static_cast<std::uint16_t>(raw) : std::uint16_t(0);
      mrow[u] = f.moving[i] ? 255 : 0;
    }
  }
}

// One frame's boxes YOLO style: class cx cy w h conf, normalised to the image size.
void write_yolo_detections(std::ostream& det, const dyncull::sim::FrameData& f) {
  det << std::setprecision(6);
  for (const auto& d : f.detections) {
    const auto c = d.box.centre();
    det << d.class_id << ' ' << c.x() / f.width << ' ' << c.y() / f.height << ' ' << d.box.width() / f.width << ' '
        << d.box.height() / f.height << ' ' << d.confidence << '\n';
  }
}

// The frame's images (rgb, depth, instance, moving) and detections (YOLO text and JSON) under `out`;
// false when one cannot be written.
bool write_frame_files(const std::filesystem::path& out, int index, const std::string& ts,
                       const dyncull::sim::FrameData& f, const cv::Mat& bgr, const cv::Mat& depth16,
                       const cv::Mat& instance16, const cv::Mat& moving8) {
  const std::string rgb_name = "rgb/" + ts + ".png";
  const bool written = cv::imwrite((out / rgb_name).string(), bgr) &&
                       cv::imwrite((out / ("depth/" + ts + ".png")).string(), depth16) &&
                       cv::imwrite((out / "instance" / (ts + ".png")).string(), instance16) &&
                       cv::imwrite((out / "moving" / (ts + ".png")).string(), moving8);
  char json_name[32];
  std::snprintf(json_name, sizeof json_name, "%06d.json", index);
  const bool json_written = write_json_detections(out / "detections_json" / json_name, index, ts, rgb_name, f);
  std::ofstream det(out / ("detections/" + ts + ".txt"));
  if (!written || !json_written || !det) return false;
  write_yolo_detections(det, f);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using namespace dyncull::sim;
  if (argc < 2) return usage("missing OUTDIR");
  const fs::path out = argv[1];
  SceneOptions options;
  std::string family, why;
  if (!parse_scene_options(argc, argv, &options, &family, &why)) return usage(why.c_str());
  const Scene scene(options);
  if (!scene.ok()) return usage(scene.reason().c_str());

  std::error_code ec;
  for (const char* sub : {"rgb", "depth", "detections", "detections_json", "instance", "moving"}) {
    fs::create_directories(out / sub, ec);
    if (ec) {
      std::cerr << "write_tum_sequence: cannot create " << (out / sub) << ": " << ec.message() << "\n";
      return 1;
    }
  }
  std::ofstream rgb_txt(out / "rgb.txt"), depth_txt(out / "depth.txt"), gt_txt(out / "groundtruth.txt"),
      assoc_txt(out / "associations.txt"), det_txt(out / "detections.txt"), cam_txt(out / "camera.txt");
  if (!rgb_txt || !depth_txt || !gt_txt || !assoc_txt || !det_txt || !cam_txt) {
    std::cerr << "write_tum_sequence: cannot write the index files in " << out << "\n";
    return 1;
  }
  const std::string name = "dyncull synthetic " + family + " " + to_string(options.motion) + " seed " +
                           std::to_string(options.seed);
  rgb_txt << "# color images\n# file: '" << name << "'\n# timestamp filename\n";
  depth_txt << "# depth maps\n# file: '" << name << "'\n# timestamp filename\n";
  gt_txt << "# ground truth trajectory\n# file: '" << name << "'\n# timestamp tx ty tz qx qy qz qw\n";
  det_txt << "# detections (YOLO style: class cx cy w h conf, normalised to the image size)\n# timestamp filename\n";
  const auto cam = scene.camera();
  cam_txt << "# pinhole camera, no distortion (" << name << ")\n" << std::setprecision(10) << "fx " << cam.fx
          << "\nfy " << cam.fy << "\ncx " << cam.cx << "\ncy " << cam.cy << "\nwidth " << cam.width << "\nheight "
          << cam.height << "\ndepth_units_per_metre 5000\n";

  FrameData f;
  cv::Mat bgr, depth16(options.height, options.width, CV_16UC1), moving8(options.height, options.width, CV_8UC1);
  for (int index = 0; index < scene.num_frames(); ++index) {
    scene.render(index, &f);
    if (!f.ok()) {
      std::cerr << "write_tum_sequence: frame " << index << ": " << f.reason << "\n";
      return 1;
    }
    const std::string ts = stamp(f.timestamp);
    const cv::Mat rgb(f.height, f.width, CV_8UC3, f.rgb.data());
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    depth_and_moving_images(f, &depth16, &moving8);
    const cv::Mat instance16(f.height, f.width, CV_16UC1, f.instance.data());
    if (!write_frame_files(out, index, ts, f, bgr, depth16, instance16, moving8)) {
      std::cerr << "write_tum_sequence: cannot write frame " << index << " into " << out << "\n";
      return 1;
    }
    const std::string rgb_name = "rgb/" + ts + ".png", depth_name = "depth/" + ts + ".png",
                      det_name = "detections/" + ts + ".txt";
    rgb_txt << ts << ' ' << rgb_name << '\n';
    depth_txt << ts << ' ' << depth_name << '\n';
    assoc_txt << ts << ' ' << rgb_name << ' ' << ts << ' ' << depth_name << '\n';
    det_txt << ts << ' ' << det_name << '\n';
    const Eigen::Quaterniond q(f.world_from_cam.R);
    gt_txt << ts << std::setprecision(9) << ' ' << f.world_from_cam.t.x() << ' ' << f.world_from_cam.t.y() << ' '
           << f.world_from_cam.t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
    if ((index + 1) % 50 == 0 || index + 1 == scene.num_frames())
      std::cout << "wrote " << index + 1 << "/" << scene.num_frames() << " frames\n" << std::flush;
  }
  std::cout << "sequence '" << name << "' in " << out << "\n";
  return 0;
}
