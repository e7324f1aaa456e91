#pragma once
/// \file mapper.hpp
/// The object mapper: keyframes in one by one, the current object map out at any time.
///
/// Voxel mode (the paper, RGB-D): each detection's mask and the keyframe's depth update a
/// voxel object (voxel_object.hpp); detections are tracked in 2D against the objects seen in
/// the last keyframes and matched in 3D against the whole map (association.hpp); an object
/// enters the map after `min_observations` (omega0 = 3) observations, its label is its most
/// frequent category, its low-probability voxels are pruned at every update, and its
/// ellipsoid comes from its occupied voxels' mean depth points through the yaw builder
/// (ellipsoid_builder.hpp).
/// Boxes mode (monocular): detections are tracked by their boxes, and each object's ellipsoid
/// is fitted to its boxes (box_ellipsoid_builder.hpp).
///
/// Reads (map(), objects(), stats()) may run on other threads while keyframes are added.

#include <map>
#include <optional>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/depth_image.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/distortion.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/mapping/association.hpp"
#include "ellreloc/mapping/box_ellipsoid_builder.hpp"
#include "ellreloc/mapping/ellipsoid_builder.hpp"
#include "ellreloc/mapping/floor.hpp"
#include "ellreloc/mapping/voxel_object.hpp"

namespace ellreloc {

enum class MappingMode {
  Voxel,  ///< RGB-D keyframes with masks (a detection without a mask uses its box)
  Boxes,  ///< boxes and poses only
};
const char* toString(MappingMode mode);
bool parseMappingMode(const std::string& name, MappingMode* mode);

struct MapperOptions {
  MappingMode mode = MappingMode::Voxel;
  VoxelOptions voxels;
  TrackingOptions tracking;
  EllipsoidBuilderOptions ellipsoid;
  BoxEllipsoidOptions boxes;
  int min_observations = 3;        ///< omega0: observations before an object enters the map
  double prune_probability = 0.5;  ///< map objects lose voxels below this at each update
  /// Voxels enter the ellipsoid from this probability on: 0.75 needs two hits more than a
  /// miss, so a voxel hit by a single stray mask pixel stays out.
  double ellipsoid_min_probability = 0.75;
  int track_window = 1;         ///< 2D tracking against objects seen in the last N keyframes
  int candidate_lifetime = 10;  ///< objects not yet in the map are forgotten after N keyframes unseen
  double min_score = 0.0;       ///< detections below this score are ignored
  /// Voxel mode: estimate the up direction from the floor seen in the depth images (averaged
  /// over keyframes, weighted by the floor's share of pixels) instead of trusting
  /// ellipsoid.up, which is then only the prior. Objects are rebuilt with it when next updated.
  bool estimate_up_from_floor = false;
  FloorOptions floor;
  long min_mask_pixels = 30;  ///< smaller masks are ignored
  /// Boxes mode: the length of the world's unit (the keyframe poses') in metres. A monocular
  /// SLAM system's poses have a unit of their own (its first baseline, say), unknown in metres;
  /// the size prior (each category's typical size, in metres) is divided by it, and so is the
  /// camera envelope's margin of 1 m. Mapper::estimatedUnitMetres() reads it off the objects.
  /// Voxel mode: 1 (the depth images are in metres).
  double unit_metres = 1.0;
  /// The keyframes (detections, and depth images in voxel mode) are raw images of this distorted
  /// lens (core/distortion.hpp): each box is undistorted to the pinhole image the ellipsoids
  /// project into (whether the image border cuts it judged on the raw box), and each mask and
  /// depth image resampled there (each pixel the nearest raw one). Its intrinsics must be the
  /// mapper's.
  std::optional<Lens> lens;

  /// Empty when every field is finite and in range, else one line naming the first that is
  /// not; the Mapper's constructor throws it.
  std::string validate() const;
};

/// What one keyframe did.
struct KeyframeReport {
  int used = 0;         ///< detections integrated
  int tracked_2d = 0;   ///< associated by 2D tracking
  int matched_3d = 0;   ///< associated by 3D voxel matching
  int new_objects = 0;  ///< started a new object
  int ignored = 0;      ///< below min_score or min_mask_pixels
  /// For each detection, in the order given: the id of the object it joined (as map() and
  /// objects() name it once it is in the map: a candidate until seen min_observations times),
  /// or -1 when it was ignored. A later keyframe may join that object into an older one or
  /// forget a candidate never confirmed: Mapper::currentObjectId follows.
  std::vector<int> object_ids;
};

/// A mapped object with what the mapper knows about it.
struct MappedObject {
  MapObject object;              ///< id, category, label histogram, ellipsoid
  std::optional<Cuboid> cuboid;  ///< voxel mode: the yaw-aligned cuboid the ellipsoid is inscribed in
  int observations = 0;
  bool depth_from_size = false;  ///< boxes mode: placed by its category's typical size (narrow baseline)
  size_t voxels = 0;             ///< voxel mode: voxels held
  size_t memory_bytes = 0;       ///< voxel mode: heap memory of its voxels
};

struct MapperStats {
  int keyframes = 0;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< the up direction the ellipsoids use
  int objects = 0;                                ///< in the map
  int candidates = 0;      ///< not in the map: seen fewer than min_observations times, or no ellipsoid fits them
  int placed_by_size = 0;  ///< boxes mode: objects in the map whose depth the size prior gave
  size_t voxels = 0;
  size_t memory_bytes = 0;
};

class Mapper {
 public:
  /// Throws ellreloc::Error for invalid intrinsics or options.
  explicit Mapper(const Intrinsics& K, const MapperOptions& options = {});

  /// Adds a keyframe: world->camera pose, detections (boxes; masks in voxel mode), and the depth
  /// image in metres (voxel mode; ignored in boxes mode). Throws ellreloc::Error naming the
  /// problem for a non-finite pose, a missing, mis-sized or empty depth image, or a mask whose
  /// size differs from the camera's; the map is then left unchanged. The detections are taken in
  /// a canonical order (score highest first, then category and box): their order in the vector
  /// changes nothing.
  KeyframeReport addKeyframe(const Pose& pose, const std::vector<Detection>& detections,
                             const DepthImage* depth = nullptr);

  /// Boxes mode: refits every object whose views grew since its last fit (objects are refitted
  /// as their views grow, not at every view). Call after the last keyframe; voxel mode needs
  /// nothing.
  void finish();

  /// The host moved its keyframes (a bundle adjustment, a loop closure): `poses` holds the
  /// world->camera pose of every keyframe added so far, in the order they were added. Boxes
  /// mode: every object is fitted again to its boxes, each seen from its keyframe's new pose (as
  /// finish() does, so the map is what these poses would have made of the same associations).
  /// Voxel mode: the depth images are gone, so each voxel moves with the keyframe that last hit
  /// it (it goes where that keyframe's camera now puts it); the up estimated from the floor is
  /// measured again from each keyframe's floor at its new pose. Objects that now coincide are
  /// joined as while mapping (two tracks of one object that a drift split before a loop closed).
  /// The camera envelope follows the new poses. Throws ellreloc::Error naming the problem (the
  /// map then unchanged) when the count differs from the keyframes added or a pose is not finite.
  void updateKeyframePoses(const std::vector<Pose>& poses);

  /// Boxes mode: the world's unit in metres that the objects tell, for poses of unknown scale
  /// (MapperOptions::unit_metres): over the objects the rays of their boxes triangulate (not
  /// placed by their typical size), the median of their category's typical size (half its two
  /// larger extents) over their size in the world's unit (their boxes' half-size at the
  /// triangulated depth). The rays do not depend on the unit assumed, but the tracking does: a
  /// unit far off splits objects, so map the keyframes again with the estimate until it settles
  /// (two or three passes). nullopt with fewer than `min_objects` such objects, or in voxel mode.
  std::optional<double> estimatedUnitMetres(int min_objects = 5) const;
  /// The id that an object a KeyframeReport named has now: two objects found to be one are
  /// joined (the younger into the older, whose id stays), as while mapping or after
  /// updateKeyframePoses. nullopt for a candidate forgotten before it was confirmed (seen fewer
  /// than min_observations times, then not for candidate_lifetime keyframes) or an id never given.
  std::optional<int> currentObjectId(int id) const;

  /// The objects in the map (those with an ellipsoid), in the order they were created, and
  /// the camera envelope of the keyframes (heights and tilts along the world's up in voxel
  /// mode or with boxes.up, else along their mean image-up; widened by 1 m and 30 degrees;
  /// none before two keyframes).
  ObjectMap map() const;
  std::vector<MappedObject> objects() const;
  MapperStats stats() const;
  const Intrinsics& intrinsics() const { return K_; }
  const MapperOptions& options() const { return options_; }

 private:
  struct Track {
    int id = 0;
    VoxelObject voxels;
    std::vector<BoxView> views;       // boxes mode
    std::vector<int> view_keyframes;  // boxes mode: the keyframe of each view
    std::vector<int> integrations;    // voxel mode: the keyframe of each integrate() into `voxels`
    std::map<int, double> labels;
    int observations = 0;
    int last_seen = -1;
    bool confirmed = false;
    std::optional<MappedObject> built;  // rebuilt as a confirmed object is updated (boxes: as its views grow)
    size_t built_views = 0;             // boxes mode: views in the last fit
    int label() const;
  };
  void checkKeyframe(const Pose& pose, const std::vector<Detection>& detections, const DepthImage* depth) const;
  void addVoxelKeyframe(const Pose& pose, const std::vector<Detection>& detections, const DepthImage& depth,
                        KeyframeReport* report);
  /// Voxel mode's 2D tracking of the used detections (with their masks) against the objects seen
  /// in the last keyframes, by their projected voxels; a detection with a mask goes only to
  /// objects whose depth range holds the mask's median depth. Each one's track index, or -1.
  std::vector<int> trackVoxelDetections2D(const Pose& pose, const std::vector<Detection>& detections,
                                          const std::vector<size_t>& used, const std::vector<BinaryMask>& masks,
                                          const DepthImage& depth) const;
  /// 2D association (association.hpp) of the used detections with tracks' expected boxes
  /// (track index, its possible boxes, at least one): each used detection's track index, or -1.
  /// `gate` (expected x used) rules pairs out; empty: none.
  std::vector<int> associate2D(const std::vector<std::pair<size_t, std::vector<Box>>>& expected,
                               const std::vector<Detection>& detections, const std::vector<size_t>& used,
                               const PairGate& gate = {}) const;
  /// `cut`: per detection, whether the raw image's border cuts its box (BoxView::cut); empty
  /// when the boxes are the pinhole image's.
  void addBoxKeyframe(const Pose& pose, const std::vector<Detection>& detections, const std::vector<bool>& cut,
                      KeyframeReport* report);
  void observed(Track& track, const Detection& detection);
  void mergeDuplicateBoxTracks();
  /// Pairs with an object updated in this keyframe (the others cannot have changed), or every
  /// pair once the keyframes moved.
  void mergeDuplicateVoxelTracks(bool every_pair = false);
  /// Track `j` joins track `i` (its views, labels and observations already added there).
  void forgetJoined(size_t i, size_t j);
  std::optional<int> currentObjectIdLocked(int id) const;
  void rebuild(Track& track) const;
  /// Boxes mode: the size prior of a category, in the world's unit.
  BoxSizePrior sizePrior(int category) const;
  /// The world's up: the floor's normal when estimated, else the options' (mutex_ held).
  Eigen::Vector3d upLocked() const;

  Intrinsics K_;
  MapperOptions options_;
  mutable std::shared_mutex mutex_;
  std::vector<Track> tracks_;
  int keyframes_ = 0;
  std::vector<Pose> keyframe_poses_;  // for the map's camera envelope
  int next_id_ = 0;
  std::map<int, int> joined_into_;  // the id of a joined track -> the id of the track it joined
  Eigen::Vector3d floor_normal_sum_ = Eigen::Vector3d::Zero();
  // Each keyframe's floor normal (times its inlier share) in its camera's frame, for
  // updateKeyframePoses.
  std::vector<std::pair<int, Eigen::Vector3d>> floor_in_camera_;
  std::vector<int> raw_pixel_;  // voxel mode through a lens: each pinhole pixel's raw pixel
};

}  // namespace ellreloc
