#pragma once
/// \file coco.hpp
/// The names of the COCO-80 categories, by the 0-based ids the data files use (person 0 ...
/// toothbrush 79): for people reading summaries and pictures.

#include <array>
#include <cstddef>

namespace ellreloc {

/// The category's COCO name, or nullptr for an id outside 0..79.
inline const char* cocoCategoryName(int id) {
  static constexpr std::array<const char*, 80> kNames = {
      "person",        "bicycle",      "car",           "motorcycle",    "airplane",     "bus",
      "train",         "truck",        "boat",          "traffic light", "fire hydrant", "stop sign",
      "parking meter", "bench",        "bird",          "cat",           "dog",          "horse",
      "sheep",         "cow",          "elephant",      "bear",          "zebra",        "giraffe",
      "backpack",      "umbrella",     "handbag",       "tie",           "suitcase",     "frisbee",
      "skis",          "snowboard",    "sports ball",   "kite",          "baseball bat", "baseball glove",
      "skateboard",    "surfboard",    "tennis racket", "bottle",        "wine glass",   "cup",
      "fork",          "knife",        "spoon",         "bowl",          "banana",       "apple",
      "sandwich",      "orange",       "broccoli",      "carrot",        "hot dog",      "pizza",
      "donut",         "cake",         "chair",         "couch",         "potted plant", "bed",
      "dining table",  "toilet",       "tv",            "laptop",        "mouse",        "remote",
      "keyboard",      "cell phone",   "microwave",     "oven",          "toaster",      "sink",
      "refrigerator",  "book",         "clock",         "vase",          "scissors",     "teddy bear",
      "hair drier",    "toothbrush"};
  return id >= 0 && id < static_cast<int>(kNames.size()) ? kNames[static_cast<size_t>(id)] : nullptr;
}

}  // namespace ellreloc
