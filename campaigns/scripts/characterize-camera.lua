-- Camera characterization (dissertation chapter 7): the chart photographed in the cabinet as RAW,
-- 16-bit TIFF, 8-bit TIFF and JPEG, N frames averaged per format; each patch's value from the
-- chart's known layout once the chart is located in the photograph; the reference colours from a
-- chart-read run; then the camera's colour space (§7.1), an ICC profile (§7.2), the adapted
-- polynomial/spline mappings with model selection (§7.3) and, on the raw, the camera as a black box
-- (§7.4: spectral sensitivities from the chart-read's spectra under the lamp's standard spectrum),
-- each with training and cross-validated ΔE00. The selected model is returned, so it is stored with
-- the run.
return {
  description = "Camera characterization (chapter 7): chart photographs as RAW, TIFF 16/8 and JPEG against a chart-read run, fitted and cross-validated",
  needs = { "camera", "lamps", "dimmer", "luminance_meter" },
  parameters = {
    reference_run = { type = "string", description = "id of a finished chart-read run of the same chart (the reference L*a*b*)" },
    frames = { type = "integer", default = 25, min = 1, max = 256, unit = "frames", description = "frames averaged per format" },
    formats = { type = "array", items = "string", values = { "raw", "tiff16", "tiff8", "jpeg" },
                default = { "raw", "tiff16", "tiff8", "jpeg" }, min_items = 1, max_items = 4,
                description = "chapter 7's test cases to photograph and fit" },
    chart = { type = "string", values = { "sg", "cc24" }, default = "sg", description = "the chart in the cabinet" },
    camera = { type = "string", default = "dslr", description = "the camera's instrument id or kind (dslr, genicam)" },
    lamp = { type = "string", default = "D65", description = "the cabinet lamp to photograph under; empty = leave the cabinet as it is" },
    dimmer_percent = { type = "number", default = 100, min = 1, max = 100, unit = "%", description = "the cabinet's dimmer level" },
    cv = { type = "string", default = "loo", description = "cross-validation: loo, or kN for N folds" },
    target_lamps = { type = "array", items = "string", default = {}, max_items = 8,
                     description = "lamps to characterize the raw for besides the photographed one (TL84, CWF, A, …): from the camera's estimated sensitivities, one characterization per lamp, each with a per-patch 95 % band; a lamp's nominal CIE spectrum is warned about" },
    prior_exclude = { type = "array", items = "string", default = {}, max_items = 28,
                      description = "camspec cameras the black box's prior leaves out (the camera under test, to judge its curves against its published ones)" },
    load_timeout_s = { type = "number", default = 600, min = 0, max = 86400, unit = "s",
                       description = "how long to wait for the operator to confirm the chart before photographing anyway" },
    corners_raw = { type = "array", items = "number", default = {}, max_items = 8, min = 0, unit = "px",
                    description = "the raw photograph's chart corners x1, y1, …, x4, y4 (outer corners of the patch grid, the first patch's first, clockwise), when the locator refused it; empty = found automatically" },
    corners_tiff16 = { type = "array", items = "number", default = {}, max_items = 8, min = 0, unit = "px",
                       description = "the same for the 16-bit TIFF" },
    corners_tiff8 = { type = "array", items = "number", default = {}, max_items = 8, min = 0, unit = "px",
                      description = "the same for the 8-bit TIFF" },
    corners_jpeg = { type = "array", items = "number", default = {}, max_items = 8, min = 0, unit = "px",
                     description = "the same for the JPEG" },
    keep = { type = "array", items = "string", values = { "average", "raw", "tiff16", "tiff8", "jpeg", "preview" },
             default = { "average", "raw", "preview" }, max_items = 6,
             description = "frames kept in the image store: the averaged raw (float array), the first raw as captured, the first frame's TIFF/JPEG, a PNG preview" },
  },
  run = function(p)
    if p.reference_run == nil or p.reference_run == "" then
      error("reference_run is required: the id of a finished chart-read run of the chart in the cabinet (run chart-read first)")
    end
    -- The operator's corners, per format, from a run the locator refused (see refusal_error below).
    local corners = {}
    for _, format in ipairs(p.formats) do
      local c = p["corners_" .. format]
      if #c ~= 0 and #c ~= 8 then
        error({ class = "bad_parameter", message = string.format("corners_%s has %d numbers", format, #c),
                hint = "give 8 numbers x1,y1,x2,y2,x3,y3,x4,y4 (the outer corners of the patch grid, the first patch's first, clockwise), or none" })
      end
      if #c == 8 then corners[format] = c end
    end
    local ref = lab.runs.chart_reference(p.reference_run)
    if ref.chart ~= p.chart then
      error(string.format("reference_run %s read a %s chart, but chart = %s", p.reference_run, ref.chart, p.chart))
    end
    local a = lab.operator.request {
      action = "load_chart",
      prompt = string.format("Put the %s in the cabinet in front of the camera %s, facing it and evenly lit",
                             p.chart == "sg" and "ColorChecker SG" or "ColorChecker 24", p.camera),
      options = { "loaded", "cancel" }, default = "loaded", timeout_s = p.load_timeout_s,
      details = { chart = p.chart, where = "cabinet" },
    }
    if a.answer == "cancel" then error("the operator cancelled the characterization") end
    if p.lamp ~= "" then
      -- wait_stable reads the LS-110: it must see the cabinet's floor, not whatever it last pointed at.
      local aim = lab.operator.request {
        action = "aim_meter", prompt = "Aim the LS-110 at the cabinet floor beside the chart (spot row 4, column 5)",
        options = { "aimed", "skip" }, default = "aimed", timeout_s = p.load_timeout_s, details = { row = 3, col = 4 },
      }
      lab.log("meter: " .. aim.answer)
      lab.lamps.select(p.lamp)
      lab.dimmer.set(p.dimmer_percent)  -- the widget may have been left dark
      local stable = lab.wait_stable()  -- a warming lamp would tint the first formats differently from the last
      lab.log(string.format("%s stable after %.0f lab s", p.lamp, stable.waited_s))
    end
    lab.progress(0.1, "photographing")
    -- The reference's luminances let the locator tell patches as dark as the chart's surround (no edge of their
    -- own) from a covered chart. (Only ids and XYZ: the spectra would swell the call's journal entry.)
    local shots = lab.camera.photograph_chart { frames = p.frames, chart = p.chart, formats = p.formats, camera = p.camera,
                                                reference = { ids = ref.ids, XYZ = ref.XYZ }, keep = p.keep,
                                                corners = corners, on_refusal = "return" }
    lab.log(string.format("photographed %d frames as %s", p.frames, table.concat(p.formats, ", ")))
    -- A photograph the locator refused (no chart, partly covered, unsure) fails the run — never fitted to wrong
    -- patches —, but only after recording it with the kept frame, so the operator can find the corners in exactly
    -- that photograph and give them to the next run.
    local refusals, commands, params, shown = {}, {}, {}, nil
    for _, format in ipairs(p.formats) do
      local f = shots.formats[format]
      if f.refused then
        local kind = format == "raw" and "average" or format
        local sha
        for _, b in ipairs(shots.blobs or {}) do
          if b.kind == kind then sha = b.sha256 end
        end
        lab.record("chart/" .. format, {
          quantity = "chart_location", value = 0, unit = "confidence", instrument = shots.instrument,
          data = { format = format, refused = f.refused, blob = sha, from_corners = f.from_corners, frames = f.frames,
                   files = f.files, width = f.width, height = f.height },
        })
        refusals[#refusals + 1] = string.format("the %s photograph%s: %s", format,
                                                f.from_corners and " (with corners_" .. format .. ")" or "", f.refused.message)
        if sha then
          shown = shown or sha
          commands[#commands + 1] = string.format("colorlab locate-chart --blob %s --chart %s --reference-run %s --corners x1,y1,x2,y2,x3,y3,x4,y4",
                                                  sha, p.chart, p.reference_run)
        else
          commands[#commands + 1] = string.format("colorlab analyze locate-chart %s --chart %s --corners x1,y1,x2,y2,x3,y3,x4,y4", f.files[1], p.chart)
        end
        params[#params + 1] = string.format("-p corners_%s=[x1,y1,x2,y2,x3,y3,x4,y4]", format)
      end
    end
    if #refusals > 0 then
      error({
        class = "needs_operator",
        message = "the chart was not located in " .. table.concat(refusals, "; "),
        hint = "check that the whole chart is in the frame, lit and in focus; or find its four corners (the outer corners of the "
               .. "patch grid, the first patch's first, clockwise"
               .. (shown and "; `colorlab download " .. shown .. " --preview -o chart.png` shows the photograph" or "") .. ") "
               .. "until `" .. table.concat(commands, "` and `") .. "` locates it, then start characterize-camera again with "
               .. "the same parameters and " .. table.concat(params, " "),
      })
    end
    local out = { reference_run = p.reference_run, chart = p.chart, frames = p.frames, lamp = p.lamp,
                  instrument = shots.instrument, formats = {} }
    local best_format, best_cv
    for k, format in ipairs(p.formats) do
      local f = shots.formats[format]
      lab.record("chart/" .. format, {
        quantity = "chart_location", value = f.confidence, unit = "confidence", instrument = shots.instrument,
        data = { format = format, corners = f.corners, from_corners = f.from_corners, rotation_deg = f.rotation_deg, patches_detected = f.patches_detected,
                 reprojection_rms_px = f.reprojection_rms_px, check = f.check, frames = f.frames, files = f.files,
                 width = f.width, height = f.height, notes = f.notes },
      })
      local unit = format == "raw" and "DN above black" or (f.bits == 8 and "8-bit code" or "16-bit code")
      for i, id in ipairs(f.ids) do
        lab.record("patch/" .. format .. "/" .. id, {
          quantity = "camera_rgb", value = f.values[i][2], unit = unit, instrument = shots.instrument,
          data = { id = id, format = format, rgb = f.values[i], detected = f.detected[i] },
        })
      end
      lab.progress(0.1 + 0.9 * (k - 0.5) / #p.formats, "fitting " .. format)
      -- The black box (raw only) takes the lamp's spectrum to be its standard illuminant's.
      local c = lab.analysis.characterize(f, ref, { cv = p.cv, lamp = p.lamp, prior_exclude = p.prior_exclude,
                                                    target_lamps = p.target_lamps })
      -- Issue 26: one characterization per other lamp, named by it, from the sensitivities the raw gives.
      for lamp, x in pairs(c.across_lamps or {}) do
        for _, w in ipairs(x.warnings) do lab.log("warning: " .. w) end
        lab.record("characterization/" .. format .. "/lamp/" .. lamp, {
          quantity = "delta_e00_cv_mean", value = x.cv.mean, unit = "ΔE00", instrument = shots.instrument,
          data = { format = format, lamp = lamp, method = x.method, lamp_measured = x.lamp_measured, warnings = x.warnings,
                   uncertainty95 = x.uncertainty95, model = x.model },
        })
      end
      for name, approach in pairs(c.approaches) do
        lab.record("characterization/" .. format .. "/" .. name, {
          quantity = "delta_e00_cv_mean", value = approach.cv.mean, unit = "ΔE00", instrument = shots.instrument,
          data = { format = format, approach = name, training = approach.training, cv = approach.cv, cv_name = c.cv },
        })
      end
      local chosen = c.approaches.adapted_mapping.cv.mean
      lab.log(string.format("%s fitted: adapted mapping %s, CV mean ΔE00 %.2f%s", format, c.selected.method, chosen,
                            c.approaches.black_box and string.format("; black box %.2f", c.approaches.black_box.cv.mean) or ""))
      if best_cv == nil or chosen < best_cv then best_format, best_cv = format, chosen end
      out.formats[format] = { confidence = f.confidence, rotation_deg = f.rotation_deg, corners = f.corners,
                              check = f.check, approaches = c.approaches, best_approach = c.best_approach,
                              selected = c.selected, not_fitted = c.not_fitted, across_lamps = c.across_lamps }
    end
    -- The model to use from now on: the adapted mapping of the format that cross-validates best.
    out.selected = { format = best_format, cv_mean_de00 = best_cv, model = out.formats[best_format].selected }
    lab.progress(1.0, "done")
    return out
  end,
}
