-- The lab's lens calibration (issue 23, docs/verify.md "The lens calibration"): the operator places the chart at
-- several poses in front of the camera — tilted different ways, pushed towards each corner of the frame and across
-- its middle, as OpenCV's calibrateCamera needs to see the lens's focal length, principal point and distortion —; each
-- pose is photographed as RAW, the chart located without a lens (the lens is what is being calibrated) and every
-- detected patch's centroid as photographed kept; at the end the same code as `colorlab lens calibrate` fits the lens
-- (lab.analysis.calibrate_lens) and the run stores its [[lens]] table for the lab configuration, with each
-- parameter's one-σ uncertainty.
--
-- A pose the operator skips or the locator refuses is recorded and left out; fewer than 3 located poses fail the run
-- with what to do. The chart goes back to its measuring place at the end (a later characterize-camera photographs it
-- there). On the simulated lab the simulator places the chart itself from the numbers in `details` (fill: the share
-- of the frame's height the chart fills; shift_x, shift_y: its centre's offset as fractions of the frame).
local POSES = {
  { what = "its top edge tilted about 20° away from the camera, in the upper left of the frame",
    tilt_deg = 20, swing_deg = 0, rotation_deg = 0, fill = 0.57, shift_x = -0.18, shift_y = -0.15 },
  { what = "its top edge tilted about 20° towards the camera and its right edge 15° away, turned 3° clockwise, in the upper right of the frame",
    tilt_deg = -20, swing_deg = 15, rotation_deg = 3, fill = 0.53, shift_x = 0.18, shift_y = -0.15 },
  { what = "its top edge tilted about 10° away and its right edge 20° towards the camera, turned 3° anticlockwise, in the lower left of the frame",
    tilt_deg = 10, swing_deg = -20, rotation_deg = -3, fill = 0.57, shift_x = -0.18, shift_y = 0.15 },
  { what = "its top edge tilted about 15° towards the camera and its right edge 15° towards it, turned 5° clockwise, in the lower right of the frame",
    tilt_deg = -15, swing_deg = -15, rotation_deg = 5, fill = 0.53, shift_x = 0.18, shift_y = 0.15 },
  { what = "its right edge swung about 25° away from the camera, turned 4° anticlockwise, in the middle of the frame and a little nearer",
    tilt_deg = 0, swing_deg = 25, rotation_deg = -4, fill = 0.60, shift_x = 0, shift_y = 0 },
  { what = "its top edge tilted about 25° away and its right edge 10° away, turned 2° clockwise, just right of the middle and a little farther",
    tilt_deg = 25, swing_deg = 10, rotation_deg = 2, fill = 0.50, shift_x = 0.05, shift_y = 0 },
  { what = "its top edge tilted about 10° towards the camera and its right edge 20° away, turned 6° clockwise, left of the middle and a little low",
    tilt_deg = -10, swing_deg = 20, rotation_deg = 6, fill = 0.50, shift_x = -0.10, shift_y = 0.08 },
  { what = "its top edge tilted about 15° away and its right edge 25° towards the camera, turned 6° anticlockwise, right of the middle and a little high",
    tilt_deg = 15, swing_deg = -25, rotation_deg = -6, fill = 0.50, shift_x = 0.10, shift_y = -0.08 },
}

local CHART_NAMES = { sg = "ColorChecker SG", cc24 = "ColorChecker 24" }

return {
  description = "Lens calibration: the chart photographed at several poses the operator sets (tilted, swung, off-centre, near the corners), located, and the camera's lens fitted (OpenCV calibrateCamera) into a [[lens]] table for the lab configuration",
  needs = { "camera", "lamps", "dimmer" },
  parameters = {
    camera_name = { type = "string", description = "the camera body as the [[lens]] table names it, e.g. \"Canon EOS 20D #1\" (required)" },
    lens_name = { type = "string", description = "the lens as the [[lens]] table names it, e.g. \"EF 50mm f/1.8 II\" (required)" },
    focal_length_mm = { type = "number", min = 1, max = 2000, unit = "mm", description = "a zoom's focal length setting" },
    focus = { type = "string", description = "the focus setting, where it was fixed (e.g. \"1.2 m\")" },
    poses = { type = "integer", default = 8, min = 3, max = #POSES, unit = "poses",
              description = "how many of the campaign's poses to photograph (in order: the four corners first)" },
    frames = { type = "integer", default = 2, min = 1, max = 256, unit = "frames", description = "frames averaged per pose" },
    chart = { type = "string", values = { "sg", "cc24" }, default = "sg", description = "the chart the operator places" },
    camera = { type = "string", default = "dslr", description = "the camera's instrument id or kind (dslr, genicam)" },
    reference_run = { type = "string",
                      description = "a finished chart-read run of the chart: its luminances let the locator tell patches with no edge of their own from a covered chart (optional)" },
    min_confidence = { type = "number", default = 0.6, min = 0, max = 1,
                       description = "a photograph the locator is less sure of is refused (its detected patches are the calibration's points)" },
    lamp = { type = "string", default = "D65", description = "the cabinet lamp to photograph under; empty = leave the cabinet as it is" },
    dimmer_percent = { type = "number", default = 100, min = 1, max = 100, unit = "%", description = "the cabinet's dimmer level" },
    place_timeout_s = { type = "number", default = 1800, min = 0, max = 86400, unit = "s",
                        description = "how long to wait for the operator to place the chart (then the pose is skipped)" },
    keep = { type = "array", items = "string", values = { "average", "raw", "preview" }, default = { "raw", "preview" }, max_items = 3,
             description = "frames kept per pose in the image store: the first raw as captured, a PNG preview, the averaged raw" },
  },
  run = function(p)
    for _, key in ipairs({ "camera_name", "lens_name" }) do
      if p[key] == nil or p[key] == "" then
        error({ class = "bad_parameter", message = key .. " is required: the [[lens]] table names the calibration by camera and lens",
                hint = "e.g. -p camera_name=\"Canon EOS 20D #1\" -p lens_name=\"EF 50mm f/1.8 II\"" })
      end
    end
    local reference
    if p.reference_run and p.reference_run ~= "" then
      local ref = lab.runs.chart_reference(p.reference_run)
      if ref.chart ~= p.chart then
        error({ class = "bad_parameter", message = string.format("reference_run %s read a %s chart, but chart = %s", p.reference_run, ref.chart, p.chart) })
      end
      reference = { ids = ref.ids, XYZ = ref.XYZ }  -- only what the locator reads: the spectra would swell the journal
    end
    if p.lamp ~= "" then
      lab.lamps.select(p.lamp)
      lab.dimmer.set(p.dimmer_percent)
    end

    local chart = CHART_NAMES[p.chart]
    local located, poses = {}, {}
    for k = 1, p.poses do
      local pose = POSES[k]
      local step = string.format("pose/%d", k)
      lab.progress((k - 1) / (p.poses + 1), step)
      local placed = lab.operator.request {
        action = "place_chart",
        prompt = string.format("Pose %d of %d: hold or prop the %s in front of the camera %s with %s, filling about %d %% of the frame's height; the whole chart in view, lit and in focus",
                               k, p.poses, chart, p.camera, pose.what, math.floor(pose.fill * 100 + 0.5)),
        options = { "placed", "skip" }, default = "skip", timeout_s = p.place_timeout_s,
        details = { pose = k, chart = p.chart, tilt_deg = pose.tilt_deg, swing_deg = pose.swing_deg,
                    rotation_deg = pose.rotation_deg, fill = pose.fill, shift_x = pose.shift_x, shift_y = pose.shift_y },
      }
      local summary = { pose = k, what = pose.what }
      if placed.answer ~= "placed" then
        summary.skipped = placed.by .. " answered " .. placed.answer
        lab.record(step, { quantity = "patches_detected", value = 0, unit = "patches", data = summary })
      else
        local shot = lab.camera.photograph_chart {
          frames = p.frames, chart = p.chart, formats = { "raw" }, camera = p.camera, reference = reference,
          min_confidence = p.min_confidence, keep = p.keep, centres = true, on_refusal = "return",
        }
        local raw = shot.formats.raw
        summary.blobs = {}
        for _, b in ipairs(shot.blobs or {}) do summary.blobs[#summary.blobs + 1] = b.sha256 end
        if raw.refused then
          summary.refused = raw.refused
          lab.record(step, { quantity = "patches_detected", value = 0, unit = "patches", instrument = shot.instrument, data = summary })
        else
          summary.confidence, summary.patches_detected = raw.confidence, raw.patches_detected
          summary.reprojection_rms_px, summary.corners = raw.reprojection_rms_px, raw.corners
          lab.record(step, { quantity = "patches_detected", value = raw.patches_detected, unit = "patches",
                             instrument = shot.instrument, data = summary })
          located[#located + 1] = { chart = p.chart, width = raw.width, height = raw.height, observed_px = raw.observed_px }
        end
      end
      poses[#poses + 1] = summary
    end

    lab.progress(p.poses / (p.poses + 1), "chart back")
    lab.operator.request {
      action = "place_chart",
      prompt = string.format("Put the %s back at its measuring place in the cabinet, facing the camera %s as characterize-camera photographs it",
                             chart, p.camera),
      options = { "placed", "skip" }, default = "skip", timeout_s = p.place_timeout_s,
      details = { pose = "measurement", chart = p.chart },
    }

    if #located < 3 then
      local why = {}
      for _, s in ipairs(poses) do
        why[#why + 1] = string.format("pose %d %s", s.pose, s.skipped or (s.refused and ("refused: " .. s.refused.message)) or "located")
      end
      error({
        class = "needs_operator",
        message = string.format("only %d of %d poses located; a lens calibration needs 3 or more (%s)", #located, p.poses, table.concat(why, "; ")),
        hint = "place the chart as each prompt says with the whole chart in view, lit and in focus (each pose's photograph is kept: "
               .. "`colorlab download SHA256 --preview -o pose.png`, the pose/N records name them), then start lens-calibration again",
      })
    end

    local now = lab.now()
    local lens = lab.analysis.calibrate_lens(located, {
      camera = p.camera_name, lens = p.lens_name, focal_length_mm = p.focal_length_mm, focus = p.focus,
      date = string.sub(now.utc, 1, 10), by = "colorlab campaign lens-calibration",
    })
    for _, key in ipairs({ "fx", "fy", "cx", "cy", "k1", "k2" }) do
      local unit = (key == "k1" or key == "k2") and "1" or "px"
      lab.record("lens/" .. key, { quantity = key, value = lens[key], unit = unit, data = { sigma = lens.sigma[key] } })
    end
    lab.log(string.format("%s: %d of %d poses, %d points, RMS %.2f px; fx %.1f ± %.1f, fy %.1f ± %.1f, cx %.1f ± %.1f, cy %.1f ± %.1f, k1 %.4f ± %.4f, k2 %.4f ± %.4f",
                          lens.name, #located, p.poses, lens.points, lens.rms_px, lens.fx, lens.sigma.fx, lens.fy, lens.sigma.fy,
                          lens.cx, lens.sigma.cx, lens.cy, lens.sigma.cy, lens.k1, lens.sigma.k1, lens.k2, lens.sigma.k2))
    lab.progress(1, "calibrated")
    return { lens = lens, toml = lens.toml, poses = poses, located = #located }
  end,
}
