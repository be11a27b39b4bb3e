# Scene loading errors through the command line: each malformed file in tests/data/bad/ (written by
# scripts/make_bad_scenes.py) must make `voxlab run` exit 2 with one line naming the file and the
# defect. Messages come from loadScene() / resolveScenePath() in src/scene/.
voxlab_cli_case(bad_missing_buffer 2 "missing-buffer\\.gltf.*buffer 0 refers to external file 'missing-buffer\\.bin' which does not exist"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/missing-buffer.gltf --out @OUT@")
voxlab_cli_case(bad_index_out_of_range 2 "index-out-of-range\\.gltf.*index 7 .*out of range"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/index-out-of-range.gltf --out @OUT@")
voxlab_cli_case(bad_nan_position 2 "nan-position\\.gltf.*mesh 0 .*primitive 0.*NaN position"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/nan-position.gltf --out @OUT@")
voxlab_cli_case(bad_inf_position 2 "inf-position\\.gltf.*mesh 0 .*primitive 0.*Inf.*position"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/inf-position.gltf --out @OUT@")
voxlab_cli_case(bad_wrong_types 2 "wrong-types\\.gltf.*accessors\\[0\\]\\.count must be a non-negative integer"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/wrong-types.gltf --out @OUT@")
voxlab_cli_case(bad_node_cycle 2 "node-cycle\\.gltf.*node hierarchy has a cycle"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/node-cycle.gltf --out @OUT@")
voxlab_cli_case(bad_unsupported_required_extension 2 "unsupported-required-extension\\.gltf.*unsupported extension KHR_draco_mesh_compression.*supported: KHR_lights_punctual"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/unsupported-required-extension.gltf --out @OUT@")
voxlab_cli_case(bad_gltf_1_0 2 "gltf-1\\.0\\.gltf.*glTF version 1\\.0 is not supported"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/gltf-1.0.gltf --out @OUT@")
voxlab_cli_case(bad_no_triangles 2 "no-triangles\\.gltf.*contains no triangles"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/no-triangles.gltf --out @OUT@")
voxlab_cli_case(bad_not_json 2 "not-json\\.gltf.*is not valid JSON"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/not-json.gltf --out @OUT@")
voxlab_cli_case(bad_empty_file 2 "empty-file\\.gltf.*file is empty"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/empty-file.gltf --out @OUT@")
voxlab_cli_case(bad_accessor_out_of_range 2 "accessor-out-of-range\\.gltf.*accessor 0.*out of range"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/accessor-out-of-range.gltf --out @OUT@")
voxlab_cli_case(bad_missing_texture 2 "missing-texture\\.gltf.*image 0 refers to external file 'missing-texture\\.png' which does not exist"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/missing-texture.gltf --out @OUT@")
voxlab_cli_case(bad_corrupt_texture 2 "corrupt-texture\\.gltf.*image 0 \\('corrupt-texture\\.png'\\) cannot be decoded"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/corrupt-texture.gltf --out @OUT@")
voxlab_cli_case(bad_alpha_mode 2 "bad-alpha-mode\\.gltf.*materials\\[0\\]\\.alphaMode 'CUTOUT' is not one of OPAQUE, MASK, BLEND"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/bad-alpha-mode.gltf --out @OUT@")
voxlab_cli_case(unknown_scene_name 2 "unknown scene 'no-such-scene'.*valid scene names:.*cornell-box"
  "run --technique vct-grid --scene no-such-scene --out @OUT@")
voxlab_cli_case(missing_scene_file 2 "scene file '.*/does-not-exist\\.gltf' does not exist.*valid scene names:.*cornell-box"
  "run --technique vct-grid --scene @ROOT@/tests/data/bad/does-not-exist.gltf --out @OUT@")
