// Trains an ORB vocabulary in ORB-SLAM2's text format with ORB-SLAM2's own extractor and bundled DBoW2, for
// hosts without the published ORBvoc.txt. Train it on frames the evaluation does not use.
//
// Usage: train_vocabulary OUT.txt K L LIST [LIST ...]
//   LIST: a TUM image list (`stamp path` lines, paths relative to the list's folder; # comments).
//   Features as ORB-SLAM2's settings files: 1000 per image, scale factor 1.2, 8 levels, FAST 20 / 7.
// Built by scripts/orbslam2.sh against the ORB-SLAM2 tree it copied (ORBextractor.cc, DBoW2).
#include "ORBVocabulary.h"
#include "ORBextractor.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

// The image paths of one TUM list, made absolute through the list's folder.
std::vector<std::string> read_image_list(const std::string& list) {
  std::vector<std::string> paths;
  const std::string::size_type slash = list.find_last_of('/');
  const std::string folder = slash == std::string::npos ? std::string(".") : list.substr(0, slash);
  std::ifstream in(list.c_str());
  if (!in) {
    std::cerr << "train_vocabulary: cannot read " << list << "\n";
    std::exit(1);
  }
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string stamp, path;
    if (fields >> stamp >> path) paths.push_back(folder + "/" + path);
  }
  return paths;
}

// One image's ORB descriptors, one cv::Mat row each (DBoW2's training input).
std::vector<cv::Mat> describe(ORB_SLAM2::ORBextractor& extractor, const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    std::cerr << "train_vocabulary: cannot read image " << path << "\n";
    std::exit(1);
  }
  if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2GRAY);
  std::vector<cv::KeyPoint> keys;
  cv::Mat descriptors;
  extractor(image, cv::Mat(), keys, descriptors);
  std::vector<cv::Mat> rows;
  for (int r = 0; r < descriptors.rows; ++r) rows.push_back(descriptors.row(r).clone());
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::cerr << "usage: train_vocabulary OUT.txt K L LIST [LIST ...]\n";
    return 2;
  }
  const std::string out = argv[1];
  const int k = std::atoi(argv[2]), levels = std::atoi(argv[3]);
  if (k < 2 || levels < 1) {
    std::cerr << "train_vocabulary: K must be at least 2 and L at least 1\n";
    return 2;
  }
  ORB_SLAM2::ORBextractor extractor(1000, 1.2f, 8, 20, 7);
  std::vector<std::vector<cv::Mat> > features;
  std::size_t descriptors = 0;
  for (int a = 4; a < argc; ++a) {
    const std::vector<std::string> paths = read_image_list(argv[a]);
    for (std::size_t i = 0; i < paths.size(); ++i) {
      features.push_back(describe(extractor, paths[i]));
      descriptors += features.back().size();
    }
  }
  std::cout << "train_vocabulary: " << features.size() << " images, " << descriptors << " descriptors, k=" << k
            << " L=" << levels << std::endl;
  ORB_SLAM2::ORBVocabulary vocabulary(k, levels, DBoW2::TF_IDF, DBoW2::L1_NORM);
  vocabulary.create(features);
  vocabulary.saveToTextFile(out);
  std::cout << "train_vocabulary: " << vocabulary.size() << " words written to " << out << std::endl;
  return 0;
}
