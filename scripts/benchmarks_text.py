"""docs/benchmarks.md's fixed text: what each binary measures beyond its source's opening comment, the
stage names, and the peers measured without a numeric target."""

# What each binary measures, beyond its source's opening comment: data, peers, how to read the counters.
PROSE = {
    "bench_geometry_fundamental_bench": """Data (`tests/support/two_view.hpp`): 1000 correspondences, fx = fy = 535,
640x480, 0.5 px Gaussian noise in both images, 30 % outliers (at least 3 px off their epipolar line), five data
sets (the benchmark argument is the seed). Threshold 1 px and confidence 0.99 for every method; OpenCV pinned to one
thread. Counters: `recall` / `precision` of the true inliers, `sampson_rms_px` = RMS Sampson distance of the
noise-free true correspondences under the estimated F (how well F models the truth). With 0.5 px noise per image
P(Sampson < 1 px) = 95.4 %, the recall ceiling. Hypotheses are scored with float Sampson distances for both scalar
types; the 7-point solves, the refits and the returned F are double for `T = double`.""",
    "bench_geometry_epipolar_bench": """For packed (x, y) containers (Eigen 2-vectors, `cv::Point_<T>`, `{T x, y}`
structs) `epipolar_distances(F, points1, points2, out)` reads the pairs and writes the distances in one SSE2 pass;
other distance kinds and containers (e.g. `cv::KeyPoint`) go through a block copy. `BM_OpenCV_Epilines_Loop_Double`
gives OpenCV `cv::Point2d` input, the peer of the double rows. Without `-march` double arithmetic is 2-wide SSE2,
half the float throughput.""",
    "bench_geometry_rigid_bench": """SE(3) (`/0`) and Sim(3) (`/1`) for 100, 1000 and 10000 pairs; the counter is the
largest coefficient difference from `Eigen::umeyama`'s result.""",
    "bench_geometry_pnp_bench": """1000 (and 100) correspondences, 0.5 px noise, 30 % outliers, 8 scenes cycled,
2 px threshold, confidence 0.99, at most 1000 iterations for both; `BM_opencv_pnp_ransac/N/2` is P3P and `/N/1`
EPnP. Errors are means over the timed calls.""",
    "bench_geometry_icp_bench": """Both ICPs are forced to 30 iterations (tolerances 0), maximum correspondence distance
0.05 m; dyncull's time includes building its k-d tree. Open3D (Debian `libopen3d-dev`) is the peer when CMake finds
it (`OMP_NUM_THREADS=1`); nanoflann is the peer of the nearest-neighbour kernel.""",
    "bench_geometry_projection_bench": """`cv::rgbd::depthTo3d` would be the natural peer of `depth_to_points` but
opencv_rgbd is not among the components the build links; the naive loop writes less (no pixel index, no counts).
The voxel grid sorts 64-bit keys.""",
    "bench_geometry_rotation_centre_bench": """500 flow vectors of a 0.3 rad rotation about (350, 210), 0.5 px noise
per end, the same normalised bisectors for every solver, started at the image centre. `err_vs_ceres_px` = distance
to a tightly converged Ceres minimiser, `err_vs_truth_px` = distance to the true centre (limited by the noise).
`BM_Robust/loss/solver`: 30 % of the vectors translate (a walking person), scale 2 px; loss 0 Huber, 1 Cauchy;
`BM_FullAlgorithm2` is the whole algorithm from point containers (bisectors, fit, eq. 15 filter, eq. 16 angle).""",
    "bench_geometry_bfgs_bench": """Our BFGS needs more iterations than Ceres on the ill-conditioned quadratic (its
first step is not rescaled) but each costs a fraction of Ceres' per-iteration overhead.""",
    "bench_geometry_ransac_bench": """The affine estimator in `bench/geometry/ransac_bench.cpp` is about 25 lines:
all a user writes to put a new model on the engine.""",
    "bench_culling_box_rule_bench": """Counter `dynamic` is the same for the three implementations. Ours also fills
reasons and the deciding box index: points copied once to SoA, an SSE2 block of 16 points against all boxes, then
a 16-entry decision table.""",
    "bench_culling_depth_mask_bench": """Wall at about 3 m, a person at about 1.5 m in the box centre, 3 % Kinect holes.
`Plain` and `RobustMissingInMask` are one pass (unsigned compares OR-ed into the mask); `RobustHistogramFallback`
(no corner depth) samples at most 4096 pixels into histograms first; `Robust` is the default (`MissingDepth::Nearest`:
a hole takes the side of its nearest measured pixel), which needs distance transforms where holes are wide, and
`OpenCVNearestFill` is that rule written with OpenCV. The pipeline labels points, never this raster.""",
    "bench_culling_dynamic_probability_bench": """1000 features, 300 in 5 masks, 120 true movers. The baseline is the
paper's plain loop (mean flow, fixed threshold); the extra cost is four medians and the track store's hash map.""",
    "bench_culling_keep_mask_bench": """Compaction of 1000 features (keypoint, 32-byte descriptor row, depth) with
30 % culled, a 640x480 raster of 5 boxes, and the region predicate at random pyramid levels.""",
    "bench_culling_moving_consistency_bench": """Data for the culling benches (`tests/support/culling_scenes.hpp`):
1102 features of which 1100 tracked, 30 % on movers, 0.25 px noise per end, 640x480 float depth, 5 boxes (two
people, chair, TV, cup). `Dyncull/refits/boxes`: the number of refits and whether the fit uses only the features
outside the boxes (the default is 2/1); `PartsFloor` is our F-RANSAC plus one batch distance pass, the floor of
the 1.2x target. Without boxes every estimator is inaccurate on this small-baseline frame.""",
    "bench_culling_reprojection_check_bench": """Each track's exact 3-D point at the previous frame; `DyncullWithDepth`
the depth residual the preset uses; the OpenCV peer is `solvePnPRansac`
(P3P, 300 iterations, 2 px, 0.999) plus `projectPoints` with the same thresholds.""",
    "bench_culling_pipeline_bench": """One frame of the culling scene (about 1100 features, 5 boxes, 640x480 depth, a
keyframe 8 frames back) through `cull_frame`, against pyramidal LK (21x21, 3 levels) of the same features between
two textured 640x480 frames. `RecommendedWithout/k` switches one stage off (0 assignment of overlapping masks by
depth, 1 depth mask, 2 sub-box, 3 moving consistency, 4 box tracker, 5 low-level shelter by depth). Counters:
precision and recall of the dynamic labels against the scene's truth, and which optional stages ran.""",
    "bench_culling_culler_bench": """`Culler` (`culling/culler.hpp`) does everything the recommended preset needs per
frame: guided descriptor matching to its keyframe, 3-D points from the keyframe's depth, track ids, keyframe
decisions and `cull_frame`. 30 frames of the synthetic walking scene, 1000 ORB features each; the first frame (no
keyframe yet) is not timed. The CPU time of `BM_CullerPerFrame` is one pass over the sequence; the per-frame figure
is the counter `frame_us`, and `vs_orb` divides it by ORB's median time on the same frames, measured in the binary.""",
    "bench_culling_keyframe_matcher_bench": """`BM_KeyframeMatcher/k`: the guided matching alone, with its variants;
`BM_OpenCvPyrLK/window/levels` shows what optical flow of the same points would cost.""",
    "bench_culling_stages_bench": """The earlier stages run once before the timed loop; the loop repeats only the
stage named.""",
    "bench_culling_allocations_bench": """Counts `operator new` calls inside `cull_frame` (a counting global allocator
in this binary only), so its times include that count.""",
    "bench_sim_scene_bench": """Rendering is ray casting of 640x480 frames with the Kinect-like depth model
(`BM_RenderFrame/motion/depth model`); the OpenCV depth-noise peer does less (no discontinuity holes, no border band).
`BM_FrontEndPull/motion/culled/wall contrast %`: OpenCV ORB (1500 features), cross-checked Hamming matching,
`solvePnPRansac` (SQPnP, 200 iterations, 2 px) between frames i and i + 5 for 40 pairs, with all features (`/0`) or
with the features on moving truth removed (`/1`, an oracle culling); one deterministic iteration each, so its
counters do not depend on the load. People pull a two-frame PnP-RANSAC off by little: RANSAC rejects most moving
features; the ATE effect of culling is measured on whole sequences (results.md).""",
    "bench_eval_ate_bench": """A 2000-pose estimate at 30 Hz (3 mm position noise, 0.17 deg rotation noise, 3 ms
stamp jitter, in another world frame) against a 100 Hz ground truth of 6677 poses. The reference in the same
binary is `associate.py`'s algorithm ported literally (O(n m) candidates, sort, greedy). Accuracy against the TUM
scripts is checked by tests, not here.""",
}

STAGE_TEXT = {
    "BM_Stage_Inputs": "inputs (contract checks)",
    "BM_Stage_Boxes": "boxes (detection filter, tracker)",
    "BM_Stage_Semantic": "semantic (box rule, depth masks)",
    "BM_Stage_Geometric": "geometric (epipolar and reprojection checks)",
    "BM_Stage_Probability": "dynamic probability",
    "BM_Stage_RegionVotes": "region votes (coherent cells, sub-boxes)",
    "BM_Stage_MultiView": "multi-view check",
    "BM_Stage_Combine": "combine (evidence, static history, guard)",
}


OTHER_PEERS = [
    ("bench_geometry_ransac_bench", "generic LO-RANSAC, 2-D affine, 30 % outliers", "BM_Dyncull_RansacAffine/30",
     "`cv::estimateAffine2D`", "BM_OpenCV_EstimateAffine2D/30"),
    ("bench_geometry_ransac_bench", "generic LO-RANSAC, 2-D affine, 60 % outliers", "BM_Dyncull_RansacAffine/60",
     "`cv::estimateAffine2D`", "BM_OpenCV_EstimateAffine2D/60"),
    ("bench_geometry_fundamental_bench", "8-point on the true inliers", "BM_Ours_8Point_Inliers",
     "`findFundamentalMat` FM_8POINT", "BM_OpenCV_FM_8POINT_Inliers"),
    ("bench_geometry_pnp_bench", "pose refinement (LM), 1000 points", "BM_dyncull_refine_pose/1000",
     "`cv::solvePnPRefineLM`", "BM_opencv_refine_lm/1000"),
    ("bench_geometry_projection_bench", "project 1000 points (float)", "BM_dyncull_project_points<float>",
     "`cv::projectPoints`", "BM_opencv_project_points"),
    ("bench_geometry_projection_bench", "depth to points, 640x480 with a mask", "BM_dyncull_depth_to_points/1",
     "naive per-pixel back-projection loop", "BM_naive_depth_to_points"),
    ("bench_geometry_bfgs_bench", "BFGS, Rosenbrock", "BM_Dyncull_Bfgs<Rosenbrock>", "Ceres BFGS",
     "BM_Ceres_Bfgs<Rosenbrock>"),
    ("bench_geometry_bfgs_bench", "BFGS, 6-D quadratic, condition 1e4", "BM_Dyncull_Bfgs<Quadratic6>", "Ceres BFGS",
     "BM_Ceres_Bfgs<Quadratic6>"),
    ("bench_geometry_icp_bench", "k-d tree nearest neighbours, 5000 queries", "BM_dyncull_kdtree_nn/12",
     "nanoflann (leaf 10)", "BM_nanoflann_kdtree_nn/10"),
    ("bench_culling_box_rule_bench", "box rule, 1000 keypoints x 5 boxes", "BM_BoxRule_Dyncull/5",
     "`cv::Rect2f::contains` loop", "BM_BoxRule_OpenCVRectContains/5"),
    ("bench_culling_keep_mask_bench", "keep-mask compaction, 1000 features", "BM_Keep_Compact",
     "`push_back` + `Mat::push_back`", "BM_Keep_OpenCVRebuild"),
    ("bench_culling_keep_mask_bench", "dynamic-region raster, 640x480, 5 boxes", "BM_Keep_Rasterise",
     "`setTo` + `cv::rectangle`", "BM_Keep_OpenCVRectangles"),
    ("bench_culling_descriptor_switch_bench", "Hamming matching, 1000 x 1000", "BM_MatchHamming/1000/0",
     "`cv::BFMatcher`", "BM_OpenCvBfMatcherHamming/1000/0"),
    ("bench_culling_descriptor_switch_bench", "L2 matching, 1000 x 1000, 256 floats", "BM_MatchL2/1000/256",
     "`cv::BFMatcher`", "BM_OpenCvBfMatcherL2/1000/256"),
    ("bench_culling_descriptor_switch_bench", "5 nearest of 200 keyframes (eq. 18)", "BM_NearestKeyframes/200",
     "`cv::norm` loop + partial sort", "BM_OpenCvNormKeyframes/200"),
    ("bench_culling_reprojection_check_bench", "reprojection check, ~1100 tracks", "BM_ReprojectionCheck_Dyncull",
     "`solvePnPRansac` + `projectPoints`", "BM_ReprojectionCheck_OpenCV"),
    ("bench_culling_subbox_refine_bench", "sub-box mask with 15 px dilation", "BM_SubBox_Mask_Dyncull", "`cv::dilate`",
     "BM_SubBox_Mask_PeerCvDilate"),
    ("bench_culling_multiview_check_bench", "multi-view region growing", "BM_MultiView_Grow_Dyncull",
     "`cv::floodFill`", "BM_MultiView_Grow_PeerCvFloodFill"),
    ("bench_culling_detections_bench", "YOLO text, 20 boxes", "BM_ParseYolo_Dyncull", "`std::istringstream` loop",
     "BM_ParseYolo_Istringstream"),
    ("bench_eval_ate_bench", "TUM association, 2000 poses", "BM_Associate/2000", "`associate.py`'s algorithm in C++",
     "BM_AssociateNaiveAssociatePy/2000"),
    ("bench_sim_scene_bench", "Kinect depth model", "BM_DepthNoise", "OpenCV noise + quantisation (less work)",
     "BM_DepthNoiseOpenCv"),
]

