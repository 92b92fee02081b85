// auvdock detect (--images "DIR/*.jpg" | --video FILE) --calib FILE [--camera NAME] --dock FILE
//                --out DIR
//                [--overlay] [--labels FILE [--label-max-range M]] [--colour C] [--deinterlace]
//                [--no-tracking] [--no-second-look] [--keep-unexplained] [--bridge B]
//                [--gravity-camera X Y Z] [--min-halo-excess GRAY]
//
// A first look at one's own footage: the real-water light detector, the identification and the
// mono pose on every image, in name order, or on every frame of a video (footage_source.h: frames
// named frame_NNNNNN, timed by the file's time stamps). MonoLightPipeline does each, with a
// second look for the lights
// that the first pass missed where the tracked or the new pose puts them, and over the whole image
// at laxer thresholds when there is no pose; --no-second-look: the first pass only); the halo
// colour threshold is learned from the identified lights (HaloColourLearner) unless given. The
// detections that an image's pose leaves unidentified, far from every light it puts in the image
// (MonoLightPipeline step 6), are reported as rejected candidates ("not a light of the dock at
// the pose"), not as detections; --keep-unexplained keeps them. At the end of the images
// (two_way_light_bridge.h; --bridge forward: walks forward in time only, as a live system could;
// off: neither): a tracked chain of poses that a longer chain's walk refutes (it labels more of
// the frame where they meet) loses its poses ("refuted" in frames.csv), and the frames without a
// pose are bridged from the chains before and after them: the lights such a walk identifies get
// their ids, what it finds far from every light is rejected ("not a light of the dock at the
// neighbouring frames' pose"), and a close light's candidate rejected for its colour alone
// (RejectedLightCandidate::overrulable: a light within decimetres of the lens whitens its glow),
// or a saturated disc wider than any blob (saturated_disc.h), where the walk puts a light becomes
// that light's detection; their reason in frames.csv says so, and summary.json counts them
// (bridged_frames.rejected_candidates_accepted). Writes
// (detect_output.h), flushed frame by frame (a stopped run keeps every frame written before the stop, as it was
// before the end), and written anew from memory when the end changed anything (each file to a
// temporary, renamed over the old one; the overlays of the bridged frames are drawn again):
//   OUTDIR/detections.csv  frame,image,light_id,u,v,radius,score,cov_uu,cov_uv,cov_vv,at_border
//                          (light_id -1: not identified; covariance in px^2)
//   OUTDIR/frames.csv      frame,image,detections,identified,status,tracked,rms_px,sigma_px,
//                          tx,ty,tz,qx,qy,qz,qw (T_C_D, empty without a pose),symmetry,reason
//   OUTDIR/camera_poses.tum  T_D_C per frame with a pose, time = frame / rate_hz of the camera
//   OUTDIR/camera_pose_covariance.csv  the covariance of each of those poses, in run's
//                          covariance.csv format (io/pose_covariance_csv.h: timestamp_ns =
//                          frame / rate_hz, tangent [dp_D, dtheta_D] of T_D_C), from each light's
//                          own centroid covariance and the fit's variance factor (SolvePnp)
//   OUTDIR/summary.json    counts, the reasons' counts, the rejected candidates' counts by kind,
//                          time per frame, and with --labels the evaluation against the labels
//                          (detection_evaluation.h)
//   OUTDIR/rejected.csv    (--overlay) frame,image,u,v,sigma,reason of every blob candidate
//                          that failed a check
//   OUTDIR/overlay/IMAGE.png (--overlay) detections (green: identified, with the id; yellow:
//                          not identified), rejected candidates (red, with the reason's initial)
// Bad input (no image matches, an image of another size than calibrated, a grey image where
// the dock's lights have a colour, unreadable calibration, dock or labels): one line, exit 2.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "apps/commands.h"
#include "apps/detect_output.h"
#include "apps/footage_source.h"
#include "apps/help_text.h"
#include "apps/reason_class.h"
#include "apps/signal_flag.h"
#include "apps/vision_frame_source.h"
#include "auvdock/eval/detection_evaluation.h"
#include "auvdock/io/camera_file.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/cancellation.h"
#include "auvdock/io/dock_io.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/light_labels_csv.h"
#include "auvdock/io/staged_directory.h"
#include "auvdock/vision/identified_light_pose.h"
#include "auvdock/vision/mono_light_pipeline.h"
#include "auvdock/vision/saturated_disc.h"
#include "auvdock/vision/two_way_light_bridge.h"

namespace fs = std::filesystem;

namespace auvdock::cli {
namespace {

struct DetectOptions {
  std::string images;
  std::string video;
  std::string calib;
  std::string camera;
  std::string dock;
  std::string out;
  std::string labels;
  std::string colour;
  bool overlay = false;
  bool deinterlace = false;
  bool no_tracking = false;
  bool no_second_look = false;
  bool keep_unexplained = false;
  bool quiet = false;
  std::string bridge = "both";
  std::vector<double> gravity_camera;
  double min_halo_excess = -1.0;  // < 0: learned from the identified lights
  double label_max_range_m = -1.0;  // < 0: every ok label is required
  std::string detector = "blob";
  std::string detector_model;  // empty: the shipped one
};


void DrawOverlay(const cv::Mat& image, const std::vector<LightDetection>& detections,
                 const std::vector<int>& ids, const std::vector<RejectedLightCandidate>& rejected,
                 const std::string& path) {
  cv::Mat vis = image.channels() == 3 ? image.clone() : cv::Mat();
  if (vis.empty()) cv::cvtColor(image, vis, cv::COLOR_GRAY2BGR);
  for (const RejectedLightCandidate& r : rejected) {
    const cv::Point p(cvRound(r.uv.x()), cvRound(r.uv.y()));
    cv::drawMarker(vis, p, cv::Scalar(0, 0, 255), cv::MARKER_TILTED_CROSS, 6, 1);
  }
  for (size_t i = 0; i < detections.size(); ++i) {
    const LightDetection& d = detections[i];
    const cv::Point p(cvRound(d.uv.x()), cvRound(d.uv.y()));
    const bool identified = i < ids.size() && ids[i] >= 0;
    const cv::Scalar colour = identified ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 255, 255);
    cv::circle(vis, p, std::max(4, cvRound(d.radius_px * 1.5)), colour, 1, cv::LINE_AA);
    cv::drawMarker(vis, p, colour, cv::MARKER_CROSS, 5, 1);
    if (identified) {
      cv::putText(vis, std::to_string(ids[i]), p + cv::Point(8, -8), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                  colour, 1, cv::LINE_AA);
    }
  }
  cv::imwrite(path, vis);
}

// A pose's residual per axis, a posteriori: rms_px sqrt(n / (2 n - 6)) for n lights (0 with 3 or
// fewer: no degrees of freedom left).
double ResidualSigmaPerAxis(double rms_px, int num_lights) {
  return num_lights > 3 ? rms_px * std::sqrt(num_lights / (2.0 * num_lights - 6.0)) : 0.0;
}

struct WalkRevision {
  int refuted = 0, identified = 0, unexplained = 0, accepted = 0;
};

// The records revised by the walks of the end (two_way_light_bridge.h): a refuted frame loses
// its pose and identities; a bridged one gets the walk's identities, and what the walk judged no
// light of the dock moves to its rejected candidates (unless keep_unexplained), and a candidate
// rejected on appearance alone, or a saturated disc, where the walk put a light
// (FewLightTracker's doubtful candidates) becomes that light's detection. Each says so in its
// reason; a refuted frame's reason class is counted in no_pose_reasons.
WalkRevision ReviseByTheWalks(const std::vector<BridgedFrame>& frames, bool keep_unexplained,
                              std::vector<FrameRecord>* records,
                              std::map<std::string, int>* rejected_reasons,
                              std::map<std::string, int>* no_pose_reasons) {
  const std::string not_a_light = "not a light of the dock at the neighbouring frames' pose";
  WalkRevision revision;
  for (size_t k = 0; k < records->size(); ++k) {
    FrameRecord& record = (*records)[k];
    const BridgedFrame& walked = frames[k];
    if (walked.refuted) {
      ++revision.refuted;
      const std::string from = std::to_string((*records)[walked.refuted_by].index);
      record.reason =
          walked.contradicted > 0
              ? "refuted: its lone pose (" + std::to_string(walked.identified()) + " lights) takes " +
                    std::to_string(walked.contradicted) +
                    " detections for lights that the run of poses from frame " + from +
                    " judges no light of the dock"
              : "refuted: its tracked pose (" + std::to_string(walked.identified()) +
                    " lights) is refuted by the longer run of poses from frame " + from +
                    ", whose walk labels more of its detections";
      record.no_pose_class =
          walked.contradicted > 0
              ? "refuted: a lone pose whose lights the neighbouring run of poses finds none"
              : "refuted by a longer run of poses";
      ++(*no_pose_reasons)[record.no_pose_class];
      record.status = "refuted";
      record.tracked = false;
      record.T_C_D.reset();
      record.light_ids.assign(record.detections.size(), -1);
    }
    if (!walked.bridged) continue;
    std::vector<LightDetection> kept;
    std::vector<int> ids;
    int identified = 0, unexplained = 0;
    for (size_t i = 0; i < record.detections.size(); ++i) {
      const LightDetection& d = record.detections[i];
      if (walked.unexplained[i] && !keep_unexplained) {
        ++unexplained;
        ++(*rejected_reasons)[not_a_light];
        record.rejected.push_back({d.uv, d.radius_px, not_a_light});
        continue;
      }
      kept.push_back(d);
      ids.push_back(walked.light_ids[i]);
      identified += ids.back() >= 0;
    }
    int accepted = 0;
    for (size_t i = 0; i < walked.doubtful.size(); ++i) {
      if (walked.doubtful_light_ids[i] < 0) continue;
      const LightDetection& d = walked.doubtful[i];
      kept.push_back(d);
      ids.push_back(walked.doubtful_light_ids[i]);
      ++accepted;
      record.rejected.erase(
          std::remove_if(record.rejected.begin(), record.rejected.end(),
                         [&](const RejectedLightCandidate& r) { return r.uv == d.uv; }),
          record.rejected.end());
    }
    revision.identified += identified + accepted;
    revision.unexplained += unexplained;
    revision.accepted += accepted;
    const int anchor = (*records)[walked.anchor_frame].index;
    record.reason += (record.reason.empty() ? "" : "; ") + std::to_string(identified) +
                     " identified and " + std::to_string(unexplained) +
                     " unexplained by the poses of the frames from " + std::to_string(anchor) +
                     (anchor > record.index ? " back" : " on");
    if (accepted > 0) {
      record.reason += "; " + std::to_string(accepted) +
                       " candidates that the detector did not take (rejected on appearance, or a "
                       "saturated disc) lie where they put a light and are taken as it";
    }
    record.detections = std::move(kept);
    record.light_ids = std::move(ids);
  }
  return revision;
}

// A frame without a pose of its own whose lights a walk identified (at least 4) gets the pose
// of those lights (identified_light_pose.h), started at the walk's pose; a light that does not
// fit it loses its identity. Its reason and the no-pose counts say so. Returns how many frames
// were posed.
int PoseFromTheWalksLabels(const CameraCalibration& camera, const DockModel& dock,
                           const std::vector<BridgedFrame>& frames,
                           std::vector<FrameRecord>* records,
                           std::map<std::string, int>* no_pose_reasons) {
  int posed = 0;
  for (size_t k = 0; k < records->size(); ++k) {
    FrameRecord& record = (*records)[k];
    const BridgedFrame& walked = frames[k];
    if (record.T_C_D || !walked.bridged || !walked.walk_T_C_D) continue;
    const IdentifiedLightPose pose = PoseFromIdentifiedLights(
        camera, dock, record.detections, record.light_ids, *walked.walk_T_C_D);
    if (!pose.T_C_D) continue;
    int left_out = 0;
    for (size_t i = 0; i < record.light_ids.size(); ++i) {
      left_out += record.light_ids[i] >= 0 && pose.light_ids[i] < 0;
    }
    record.light_ids = pose.light_ids;
    record.T_C_D = pose.T_C_D;
    record.covariance_local = pose.covariance_local;
    record.rms_px = pose.rms_px;
    record.pixel_sigma_px = pose.pixel_sigma_px;
    record.residual_sigma_px = ResidualSigmaPerAxis(pose.rms_px, pose.num_lights);
    record.status = "ok";
    record.tracked = false;
    record.reason = "posed from the " + std::to_string(pose.num_lights) +
                    " lights that the walk identified" +
                    (left_out > 0 ? " (" + std::to_string(left_out) +
                                        " more left out: not fitting that pose)"
                                  : std::string()) +
                    " (on its own: " + record.reason + ")";
    record.symmetry = "identities carried by the walk from frame " +
                      std::to_string((*records)[walked.anchor_frame].index);
    auto count = no_pose_reasons->find(record.no_pose_class);
    if (count != no_pose_reasons->end() && --count->second == 0) no_pose_reasons->erase(count);
    ++posed;
  }
  return posed;
}

void RunDetect(const DetectOptions& options) {
  if (options.images.empty() == options.video.empty()) {
    throw InputError("detect: give the footage as --images \"DIR/*.jpg\" or as --video FILE");
  }
  const CameraCalibration camera = LoadCameraCalibration(options.calib, options.camera);
  FootageSource footage = options.video.empty()
                              ? FootageSource::Images(options.images, camera.rate_hz)
                              : FootageSource::Video(options.video, camera.rate_hz);
  const char* unit = footage.is_video() ? "video frames" : "images";
  const DockModel dock = LoadDockModel(options.dock);
  // The walks of the end (two_way_light_bridge.h), which follow tracked poses.
  const bool walks = options.bridge != "off" && !options.no_tracking;
  LightColour colour;
  try {
    colour = ParseLightColour(options.colour.empty() ? dock.light_colour : options.colour);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--colour: ") + e.what());
  }
  std::optional<LightLabels> labels;
  if (!options.labels.empty()) labels = LoadLightLabels(options.labels);

  MonoLightPipelineOptions pipeline_options;
  pipeline_options.detector.deinterlace = options.deinterlace;
  pipeline_options.detector.checks.colour = colour;
  if (options.detector == "learned") {
    pipeline_options.learned_first_pass = true;
    pipeline_options.learned.model_path =
        options.detector_model.empty() ? DefaultLightNetModel() : options.detector_model;
    pipeline_options.learned.colour = colour;
    pipeline_options.learned.deinterlace = options.deinterlace;
  } else if (options.detector != "blob") {
    throw InputError("--detector: expected blob or learned (got '" + options.detector + "')");
  }
  if (options.min_halo_excess >= 0.0) {
    pipeline_options.detector.checks.min_halo_excess = options.min_halo_excess;
    pipeline_options.learn_colour = false;
  }
  pipeline_options.guided_search = !options.no_second_look;
  pipeline_options.weak_pass = !options.no_second_look;
  pipeline_options.keep_unexplained = options.keep_unexplained;
  MonoLightPoserOptions& poser_options = pipeline_options.poser;
  poser_options.use_tracking = !options.no_tracking;
  if (!options.gravity_camera.empty()) {
    if (options.gravity_camera.size() != 3) {
      throw InputError("--gravity-camera: expected 3 numbers (x y z in the camera frame)");
    }
    const Eigen::Vector3d g(options.gravity_camera[0], options.gravity_camera[1],
                            options.gravity_camera[2]);
    if (!(g.norm() > 0.0) || !g.allFinite()) {
      throw InputError("--gravity-camera: must be a finite, non-zero direction");
    }
    poser_options.gravity_C = g;
  }
  MonoLightPipeline pipeline(camera, dock, pipeline_options);
  const HaloColourLearner& colour_learner = pipeline.colour_learner();

  RequireAbsentOrEmptyDirectory(options.out);
  fs::create_directories(options.out);
  if (options.overlay) fs::create_directories(options.out + "/overlay");
  DetectOutput output(options.out, options.overlay);
  std::vector<FrameRecord> records;

  const CancellationToken cancel = InstallSignalCancellation();
  std::map<std::string, int> reasons;
  std::map<std::string, int> rejected_reasons;  // every image's rejected candidates, by kind
  int n_frames = 0, n_no_detection = 0;
  int n_guided = 0, n_weak_pass = 0;
  double detect_s = 0.0, pose_s = 0.0;
  bool interrupted = false;
  FootageFrame footage_frame;
  while (true) {
    if (cancel.IsCancelled()) {
      interrupted = true;
      break;
    }
    if (!footage.Next(&footage_frame)) break;
    const std::string& path = footage_frame.origin;
    const std::string& name = footage_frame.name;
    const cv::Mat& image = footage_frame.image;
    if (image.cols != camera.intrinsics.width() || image.rows != camera.intrinsics.height()) {
      throw InputError(path + ": the image is " + std::to_string(image.cols) + "x" +
                       std::to_string(image.rows) + ", the calibration " +
                       std::to_string(camera.intrinsics.width()) + "x" +
                       std::to_string(camera.intrinsics.height()));
    }
    if (image.channels() == 1 && colour != LightColour::kWhite) {
      throw InputError(path + ": a grey image, but the lights are " + LightColourName(colour) +
                       " (give --colour white to detect without colour)");
    }
    MonoLightFrame frame = pipeline.Process(image);
    const MonoPoseResult& pose = frame.pose;
    FrameRecord record;
    record.index = footage_frame.index;
    record.time_s = footage_frame.time_s;
    record.path = path;
    record.name = name;
    record.detections = frame.detections;
    record.light_ids = pose.light_ids;
    record.status = pose.T_C_D ? "ok" : MatchStatusName(pose.status);
    record.tracked = pose.tracked;
    record.T_C_D = pose.T_C_D;
    record.covariance_local = pose.covariance_local;
    record.rms_px = pose.rms_px;
    record.pixel_sigma_px = pose.pixel_sigma_px;
    if (pose.T_C_D) record.residual_sigma_px = ResidualSigmaPerAxis(pose.rms_px, pose.num_lights);
    record.rejected = std::move(frame.rejected);
    for (const RejectedLightCandidate& r : record.rejected) {
      if (!r.overrulable) continue;
      LightDetection d;
      d.uv = r.uv;
      d.radius_px = r.sigma_px;
      d.covariance = r.covariance;
      record.doubtful.push_back(d);
    }
    // A light within decimetres of the lens may be a saturated disc wider than any blob (only the
    // walks of the end use doubtful candidates).
    if (walks) {
      for (const LightDetection& d : FindSaturatedDiscs(image)) record.doubtful.push_back(d);
    }
    for (const LightDetection& d : frame.unexplained) {
      record.rejected.push_back({d.uv, d.radius_px, "not a light of the dock at the pose"});
    }
    const std::vector<LightDetection>& detections = record.detections;
    const std::vector<RejectedLightCandidate>& rejected = record.rejected;
    detect_s += frame.detect_s;
    pose_s += frame.identify_s;
    ++n_frames;
    n_guided += frame.guided_detections;
    n_weak_pass += frame.from_weak_pass;
    if (detections.empty()) ++n_no_detection;
    // Why the detector found too few lights: its rejected candidates, by kind (a wrong colour
    // setting shows here as "wrong colour" in every image).
    std::map<std::string, int> rejected_here;
    for (const RejectedLightCandidate& r : rejected) {
      const std::string kind = r.reason.substr(0, r.reason.find(" ("));
      ++rejected_here[kind];
      ++rejected_reasons[kind];
    }
    record.reason = pose.reason;
    if (!pose.T_C_D) {
      record.no_pose_class = ReasonClass(pose.reason);
      ++reasons[record.no_pose_class];
    }
    if (!pose.T_C_D && !rejected_here.empty() &&
        static_cast<int>(detections.size()) < pipeline_options.poser.min_lights) {
      const auto most = std::max_element(
          rejected_here.begin(), rejected_here.end(),
          [](const auto& a, const auto& b) { return a.second < b.second; });
      record.reason += " (" + std::to_string(rejected.size()) + " candidates rejected; most often: " +
                       most->first + ")";
    }
    std::replace(record.reason.begin(), record.reason.end(), ',', ';');
    record.symmetry = pose.symmetry_note;
    std::replace(record.symmetry.begin(), record.symmetry.end(), ',', ';');
    output.Write(record);
    if (options.overlay) {
      DrawOverlay(image, detections, record.light_ids, rejected,
                  options.out + "/overlay/" + fs::path(name).stem().string() + ".png");
    }
    if (!options.overlay) record.rejected.clear();  // only rejected.csv needs them later
    records.push_back(std::move(record));
    if (!options.quiet && n_frames % 25 == 0) {
      if (footage.announced_frames() > 0) {
        std::fprintf(stderr, "\rdetect: %d/%d %s", n_frames, footage.announced_frames(), unit);
      } else {
        std::fprintf(stderr, "\rdetect: %d %s", n_frames, unit);
      }
    }
  }
  if (!options.quiet) std::fprintf(stderr, "\n");
  if (footage.ended_early()) {
    std::fprintf(stderr,
                 "detect: warning: the video ended after %d frames; its header announces %d "
                 "(a damaged or cut file?)\n",
                 n_frames, footage.announced_frames());
  }

  // The frames without a pose, from the posed frames beside them (two_way_light_bridge.h); the
  // files written frame by frame are then written anew with what the walks identified.
  int n_bridged = 0, n_bridge_identified = 0, n_bridge_unexplained = 0, n_refuted = 0;
  int n_bridge_accepted = 0, n_posed_from_walks = 0;
  if (!interrupted && walks) {
    std::vector<BridgedFrame> frames(records.size());
    for (size_t k = 0; k < records.size(); ++k) {
      frames[k].detections = records[k].detections;
      frames[k].T_C_D = records[k].T_C_D;
      frames[k].covariance_local = records[k].covariance_local;
      frames[k].residual_sigma_px = records[k].residual_sigma_px;
      frames[k].tracked = records[k].tracked;
      frames[k].doubtful = records[k].doubtful;
      frames[k].own_light_ids = records[k].light_ids;
    }
    TwoWayLightBridgeOptions bridge_options;
    bridge_options.backward = options.bridge == "both";
    bridge_options.tracker.pixel_noise_px = camera.pixel_noise_px;
    n_bridged = BridgeFramesWithoutPose(camera.intrinsics, dock, footage.frame_interval_s(),
                                        bridge_options, &frames);
    const WalkRevision revision =
        ReviseByTheWalks(frames, options.keep_unexplained, &records, &rejected_reasons, &reasons);
    n_refuted = revision.refuted;
    n_bridge_identified = revision.identified;
    n_bridge_unexplained = revision.unexplained;
    n_bridge_accepted = revision.accepted;
    n_posed_from_walks = PoseFromTheWalksLabels(camera, dock, frames, &records, &reasons);
    if (options.overlay) {
      for (size_t k = 0; k < records.size(); ++k) {
        if (!frames[k].refuted && !frames[k].bridged) continue;
        const cv::Mat image = footage.Reread(records[k].index);
        if (image.empty()) continue;
        DrawOverlay(image, records[k].detections, records[k].light_ids, records[k].rejected,
                    options.out + "/overlay/" + fs::path(records[k].name).stem().string() +
                        ".png");
      }
    }
    if (n_bridged > 0 || n_refuted > 0) output.Rewrite(records);
  }
  int n_pose = 0, n_tracked = 0;
  for (const FrameRecord& record : records) {
    n_pose += record.T_C_D.has_value();
    n_tracked += record.T_C_D && record.tracked;
  }
  int n_detections = 0;
  std::map<std::string, FrameDetections> evaluated;
  for (const FrameRecord& record : records) {
    n_detections += static_cast<int>(record.detections.size());
    FrameDetections& e = evaluated[record.name];
    for (const LightDetection& d : record.detections) e.uv.push_back(d.uv);
    e.has_pose = record.T_C_D.has_value();
  }

  nlohmann::ordered_json summary;
  summary["footage"] = footage.is_video() ? options.video : options.images;
  summary["images"] = footage.announced_frames();  // a video: what its header announces (0: not said)
  summary["frames"] = n_frames;
  summary["interrupted"] = interrupted;
  summary["frames_with_pose"] = n_pose;
  summary["frames_tracked"] = n_tracked;
  summary["frames_without_detection"] = n_no_detection;
  summary["detections"] = n_detections;
  summary["frames_refuted"] = n_refuted;
  summary["frames_posed_from_walks"] = n_posed_from_walks;
  summary["bridged_frames"] = {{"frames", n_bridged},
                               {"identified", n_bridge_identified},
                               {"unexplained", n_bridge_unexplained},
                               {"rejected_candidates_accepted", n_bridge_accepted}};
  summary["second_look"] = {{"guided_detections", n_guided}, {"frames_posed_by_weak_pass", n_weak_pass}};
  summary["colour"] = LightColourName(colour);
  summary["no_pose_reasons"] = reasons;
  summary["rejected_candidates"] = rejected_reasons;
  summary["halo_colour"] = {
      {"learned", colour_learner.learned()},
      {"threshold", colour_learner.threshold()},
      {"identified_median", colour_learner.median_excess() ? *colour_learner.median_excess() : 0.0}};
  summary["time_per_frame_ms"] = {{"detect", n_frames ? 1e3 * detect_s / n_frames : 0.0},
                                  {"identify_and_pose", n_frames ? 1e3 * pose_s / n_frames : 0.0}};
  std::printf("detect: %d %s -> %s: %d with a pose (%d tracked), %d detections\n", n_frames,
              unit, options.out.c_str(), n_pose, n_tracked, n_detections);
  for (const auto& [reason, count] : reasons) {
    std::printf("  no pose: %d x %s\n", count, reason.c_str());
  }
  if (n_refuted > 0) {
    std::printf("  %d poses refuted by a longer run of poses (withdrawn)\n", n_refuted);
  }
  if (n_posed_from_walks > 0) {
    std::printf("  %d frames without a pose of their own posed from the lights that the walks "
                "identified\n",
                n_posed_from_walks);
  }
  if (n_bridged > 0) {
    std::printf("  %d frames without a pose bridged by their neighbours' poses: %d lights "
                "identified (%d of them candidates the detector had rejected), %d detections no "
                "light of the dock\n",
                n_bridged, n_bridge_identified, n_bridge_accepted, n_bridge_unexplained);
  }
  if (!rejected_reasons.empty()) {
    std::vector<std::pair<int, std::string>> by_count;
    for (const auto& [kind, count] : rejected_reasons) by_count.emplace_back(count, kind);
    std::sort(by_count.rbegin(), by_count.rend());
    std::string line;
    for (const auto& [count, kind] : by_count) {
      line += (line.empty() ? "" : ", ") + std::to_string(count) + " " + kind;
    }
    std::printf("  candidates rejected: %s\n", line.c_str());
    if (n_pose == 0 && by_count.front().second == "wrong colour") {
      std::printf("  no pose in any image and most candidates had the wrong colour: are the lights "
                  "%s (--colour, dock.yaml colour)?\n",
                  LightColourName(colour));
    }
  }
  if (labels) {
    DetectionEvaluationOptions evaluation_options;
    if (options.label_max_range_m >= 0.0) evaluation_options.max_range_m = options.label_max_range_m;
    const DetectionEvaluation e = EvaluateDetections(*labels, evaluated, evaluation_options);
    summary["labels"] = {{"file", options.labels},
                         {"frames", e.frames},
                         {"frames_not_processed", e.missing_frames},
                         {"ok_labels", e.ok_labels},
                         {"recall", e.recall},
                         {"precision", e.precision},
                         {"detections", e.detections},
                         {"centroid_rms_px", e.centroid_rms_px},
                         {"centroid_median_px", e.centroid_median_px},
                         {"centroid_samples", e.centroid_samples},
                         {"pose_frames_eligible", e.pose_frames_eligible},
                         {"pose_frames", e.pose_frames},
                         {"pose_rate", e.pose_rate},
                         {"missed", e.missed},
                         {"false_detections", e.false_detections}};
    std::printf(
        "  labels: %d frames: recall %.3f (%d/%d ok), precision %.3f, centroid rms %.2f px "
        "(median %.2f, %d), pose in %d/%d frames with >= 4 ok lights (%.3f)\n",
        e.frames, e.recall, e.hits, e.ok_labels, e.precision, e.centroid_rms_px,
        e.centroid_median_px, e.centroid_samples, e.pose_frames, e.pose_frames_eligible,
        e.pose_rate);
  }
  std::ofstream(options.out + "/summary.json") << summary.dump(2) << "\n";
  if (interrupted) throw Cancelled();
}

}  // namespace

void AddDetectCommand(CLI::App& root) {
  auto options = std::make_shared<DetectOptions>();
  CLI::App* sub = root.add_subcommand(
      "detect",
      "Detect and identify the dock's lights in one's own images (mono pose per image); writes "
      "detections.csv, frames.csv, camera_poses.tum, camera_pose_covariance.csv, summary.json "
      "[, overlay/]");
  sub->footer(DetectHelp());
  CLI::Option* images =
      sub->add_option("--images", options->images, "Image files, a glob pattern: \"DIR/*.jpg\"");
  sub->add_option("--video", options->video,
                  "A video file instead of --images (what OpenCV's FFmpeg reader "
                  "opens: mp4, avi, mkv, ...); its frames are named frame_000000, frame_000001, "
                  "... in the outputs and the labels")
      ->excludes(images);
  sub->add_option("--calib", options->calib,
                  "calibration.yaml (auvdock) or an OpenCV FileStorage calibration")
      ->required();
  sub->add_option("--camera", options->camera, "Camera name in calibration.yaml");
  sub->add_option("--dock", options->dock, "dock.yaml: the light layout (and colour)")->required();
  sub->add_option("--out", options->out, "Output folder (must not exist or be empty)")->required();
  sub->add_option("--labels", options->labels,
                  "Hand labels (CSV: frame_file,u,v[,status,quality]): measure the detector");
  sub->add_option("--label-max-range", options->label_max_range_m,
                  "Require only labels nearer than this (m; labels with a range_m column, e.g. "
                  "a simulated dataset's groundtruth/<camera>_lights.csv)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--colour", options->colour,
                  "Light colour (white, blue, green, blue_green, red); default: the dock's")
      ->check(CLI::IsMember({"white", "blue", "green", "blue_green", "red"}));
  sub->add_flag("--overlay", options->overlay, "Write each image with the detections drawn");
  sub->add_flag("--deinterlace", options->deinterlace,
                "Interlaced video: detect on the even field, line-doubled");
  sub->add_option("--detector", options->detector,
                  "blob (default: scale-space blobs and checks) or learned (the network learned "
                  "from randomised renders proposes the lights: learned_light_detector.h)")
      ->check(CLI::IsMember({"blob", "learned"}));
  AddDetectorModelOption(sub, &options->detector_model);
  sub->add_flag("--no-tracking", options->no_tracking, "Identify every image from scratch (and no --bridge)");
  sub->add_flag("--keep-unexplained", options->keep_unexplained,
                "Report as detections what an image's pose leaves unidentified far from every "
                "light it predicts (by default: rejected, 'not a light of the dock at the pose')");
  sub->add_option("--bridge", options->bridge,
                  "Frames without a pose: identify their lights from the posed frames around "
                  "them (both: before and after, forward: before only, as a live system could; "
                  "off)")
      ->check(CLI::IsMember({"both", "forward", "off"}));
  sub->add_flag("--no-second-look", options->no_second_look,
                "Only the full-image pass: no search where the pose puts the missed lights, no "
                "laxer pass over an image without a pose");
  sub->add_option("--min-halo-excess", options->min_halo_excess,
                  "Fixed halo-colour threshold (gray levels); default: start permissive and learn "
                  "it from the identified lights");
  sub->add_option("--gravity-camera", options->gravity_camera,
                  "Gravity's rough direction in the camera frame (x y z; an upright camera: 0 1 0), "
                  "to tell a symmetric dock's poses apart")
      ->expected(3);
  sub->add_flag("--quiet", options->quiet, "No progress display");
  sub->callback([options] { RunDetect(*options); });
}

}  // namespace auvdock::cli
