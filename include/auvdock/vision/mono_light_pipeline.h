// One camera's lights and pose, image after image, without an IMU (the path of `auvdock
// detect`): the real-water detector, a second look where the lights should be, identification
// and PnP (MonoLightPoser), and the halo colour learned from the identified lights.
//
// Per image:
//   1. Full-image detection (BlobLightDetector) with the learned colour threshold, or, with
//      learned_first_pass, the network learned from renders (learned_light_detector.h; no
//      rejected candidates to report). Steps 2, 4 and 5 use the blob detector's machinery either
//      way.
//   2. With fewer than min_lights detections and a tracked pose from the last frames
//      (MonoLightPoser::TrackedPose), the dock lights it projects where no detection is are
//      searched for (GuidedLightSearch) with the motion since then as the gate: each prediction's
//      covariance is tracking_motion_px^2 I. (With enough detections tracking needs no guesses,
//      and step 5 finds the rest at a fraction of the cost.)
//   3. Identification and pose on the detections of 1 and 2. The detections of 2 are only guesses
//      at where a light might be, for tracking: those it did not identify are dropped, and when
//      tracking fails, the detections of 1 alone are identified from scratch.
//   4. No pose: the whole image once more with a laxer blob response and halo colour (its
//      strongest blobs, 4 more than the dock has lights) (weak_min_response, weak_halo_fraction;
//      the far, dim lights of a first approach), and only its detections that the
//      identification verifies against the dock are kept (with the first pass's other
//      detections), if its pose identifies at least weak_min_support of the lights it puts in
//      the image and sees the deck from weak_min_view_elevation_deg above its plane or more; a
//      pose that does not is neither reported nor tracked from
//      (MonoLightPoser::Retry's accept). Also after a first pass with min_lights detections or
//      more whose identification failed (weak_pass_after_failed_identification): 3 lights and a
//      bright fitting are ambiguous, the 3 dimmer lights beside them settle it.
//   5. With a pose: the lights it projects where no detection is are searched for with the
//      pose's own covariance as the gate (GuidedLightSearch), and kept with their identity. Their
//      expected size is the dock's radius_m scaled by the median ratio of the identified lights'
//      radii to their predicted ones (the glow, not the dock file, sets a light's blob size).
//   6. With a pose, the detections it leaves unidentified far from every light it puts in the
//      image are not the dock's lights by the dock model's verdict (pose_verdict.h: reflections,
//      lit fittings, clutter that passed the checks; unexplained_gate_sigmas, _floor_px,
//      _min_support): they move to MonoLightFrame::unexplained unless keep_unexplained. A
//      detection near a predicted light stays, unidentified: it may be that light, left out by
//      the matcher's gate, or part of its glow. Without a pose nothing is verified, and every
//      detection stays.
// The colour learner sees the first pass's identified lights only (the others passed a laxer
// test). Guided and weak detections are ordinary detections in the output, with their own
// centroid covariance; MonoLightFrame counts them.
//
// Units: pixels, metres; T_C_D maps dock coordinates into the camera frame (OpenCV).
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/vision/blob_light_detector.h"
#include "auvdock/vision/guided_light_search.h"
#include "auvdock/vision/halo_colour_learner.h"
#include "auvdock/vision/learned_light_detector.h"
#include "auvdock/vision/mono_light_poser.h"
#include "auvdock/vision/pose_verdict.h"

namespace auvdock {

struct MonoLightPipelineOptions {
  BlobLightDetectorOptions detector;
  bool learned_first_pass = false;
  LearnedLightDetectorOptions learned;  // learned_first_pass only
  MonoLightPoserOptions poser;
  bool learn_colour = true;  // false: detector.checks.min_halo_excess throughout
  bool guided_search = true;  // steps 2 and 5
  GuidedLightSearchOptions guided;
  // Step 2's gate: the lights' image motion between frames, 1 sigma (the tracking matcher's
  // gate, MonoLightPoserOptions::tracking_gate_px, bounds it).
  double tracking_motion_px = 10.0;
  bool weak_pass = true;  // step 4
  double weak_min_response = 12.0;
  double weak_halo_fraction = 0.3;
  double weak_min_support = 0.75;  // of the dock's lights that the weak pass's pose puts in view
  // And it must see the deck from at least this far above its plane (the matcher's own limit,
  // RansacMatcherOptions::min_view_elevation_deg, is 5 deg for the pool clip's poor camera
  // model): seen edge-on, a layout's lights lie on one image line, where a cable or a rim puts a
  // row of weak bumps (randomised renders: a cable fitted the T dock 5.3 deg up, 20 m off, while
  // every true view with 4 lights or more is at least 29 deg up; the pool clip's are 58-88).
  double weak_min_view_elevation_deg = 10.0;
  bool weak_pass_after_failed_identification = true;  // false: only after < min_lights
  bool keep_unexplained = false;  // step 6 off
  double unexplained_gate_sigmas = 3.0;
  double unexplained_floor_px = 4.0;
  double unexplained_min_support = 0.75;
};

struct MonoLightFrame {
  std::vector<LightDetection> detections;
  MonoPoseResult pose;  // pose.light_ids[i] belongs to detections[i]
  std::vector<RejectedLightCandidate> rejected;  // the first pass's candidates not kept
  std::vector<LightDetection> unexplained;        // step 6
  int first_pass_detections = 0;  // detections[0, n) are the first pass's (0 after step 4)
  int guided_detections = 0;  // kept from steps 2 and 5
  bool from_weak_pass = false;
  double detect_s = 0.0, identify_s = 0.0;  // wall time of detection (1, 2, 4, 5) and 3
};

class MonoLightPipeline {
 public:
  // Throws std::invalid_argument for options out of range.
  MonoLightPipeline(const CameraCalibration& camera, const DockModel& dock,
                    const MonoLightPipelineOptions& options = {});

  // image: CV_8UC3, or CV_8UC1 (no colour check), of the calibrated size (not checked here).
  MonoLightFrame Process(const cv::Mat& image);

  const HaloColourLearner& colour_learner() const { return colour_learner_; }

 private:
  CameraCalibration camera_;
  DockModel dock_;
  MonoLightPipelineOptions options_;
  BlobLightDetector detector_;
  std::shared_ptr<const LearnedLightDetector> learned_detector_;  // learned_first_pass only
  BlobLightDetector weak_detector_;
  GuidedLightSearch pose_search_;
  GuidedLightSearch tracked_search_;
  HaloColourLearner colour_learner_;
  MonoLightPoser poser_;
};

}  // namespace auvdock
