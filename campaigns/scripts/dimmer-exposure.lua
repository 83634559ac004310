-- Which dimmer setting to use (dissertation §6.2's end, Tables 7 and 8): one photograph of the ColorChecker SG
-- at each dimmer level, the exposure time doubled as the light halves (Table 7: f/4.0, 1/30 s at 100 %, 1/15 s
-- at 50 %, 1/8 s at 25 %, 1/4 s at 15 %), so the photographs should be equal; then the interval length
-- (max − min) of R, G and B over the chart's 14 dark border patches at each level (Table 8). ProfileMaker
-- rejected every photograph but the 100 % one because "the dark border patches are not even illuminated across
-- the chart"; the dissertation puts the spread's growth down to noise from the longer exposures.
--
-- The dark border patches: the SG's border (rows 1 and 10, columns A and N) repeats white, grey and black
-- (analysis/src/chart_layout.cpp: top and bottom rows WGKWGKWGKWGKGW left to right, column A WKGWKGWKGW and
-- column N WGKWGKWGKW top to bottom); its 14 blacks (L* 6.5) are C1 F1 I1 L1, C10 F10 I10 L10, A2 A5 A8 and
-- N3 N6 N9 — the dissertation's "14 dark border patches".
--
-- Records per level: exposure/D<level> (the camera settings used, Table 7; the chart's location; every patch's
-- value per format), dark/<format>/D<level>/<id> (each dark border patch's robust RGB) and
-- interval/<format>/D<level> (Table 8's interval lengths, R G B). The camera is left at the first level's settings
-- (the dissertation's choice, 100 % at 1/30 s) and the dimmer at 100 %.
local BORDER_TOP, BORDER_LEFT, BORDER_RIGHT = "WGKWGKWGKWGKGW", "WKGWKGWKGW", "WGKWGKWGKW"

local function dark_border_ids()
  local ids = {}
  for c = 1, 14 do
    if BORDER_TOP:sub(c, c) == "K" then
      local col = string.char(64 + c)
      ids[#ids + 1] = col .. "1"
      ids[#ids + 1] = col .. "10"
    end
  end
  for r = 2, 9 do
    if BORDER_LEFT:sub(r, r) == "K" then ids[#ids + 1] = "A" .. r end
    if BORDER_RIGHT:sub(r, r) == "K" then ids[#ids + 1] = "N" .. r end
  end
  table.sort(ids)
  return ids
end

return {
  description = "Which dimmer setting to use (Tables 7, 8): one SG photograph per dimmer level with the exposure doubled as the light halves, and the interval length of R, G, B over the 14 dark border patches",
  needs = { "camera", "lamps", "dimmer", "luminance_meter" },
  parameters = {
    levels = { type = "array", items = "number", default = { 100, 50, 25, 15 }, min_items = 1, max_items = 12, min = 1, max = 100,
               unit = "%", description = "the dimmer levels, one photograph each (Table 7's columns)" },
    shutter_s = { type = "array", items = "number", default = { 1 / 30, 1 / 15, 1 / 8, 1 / 4 }, min_items = 1, max_items = 12,
                  min = 0, unit = "s", description = "the exposure time at each level, one per level (Table 7: doubled as the light halves)" },
    aperture_f = { type = "number", default = 4.0, min = 1, max = 32, description = "the aperture at every level (Table 7: 4.0)" },
    lamp = { type = "string", default = "D65", description = "the cabinet lamp (§6.2 chose D65)" },
    frames = { type = "integer", default = 1, min = 1, max = 256, unit = "frames", description = "frames averaged per photograph (the dissertation took one)" },
    formats = { type = "array", items = "string", values = { "tiff8", "raw", "tiff16", "jpeg" }, default = { "tiff8", "raw" },
                min_items = 1, max_items = 4,
                description = "formats sampled: tiff8 is Table 8's 8-bit values; raw (linear counts above black) shows how much light each photograph got" },
    camera = { type = "string", default = "dslr", description = "the camera's instrument id or kind" },
    reference_run = { type = "string", default = "", description = "a finished chart-read run of the SG (optional): helps the locator with patches as dark as the surround" },
    settle_s = { type = "number", default = 0, min = 0, max = 3600, unit = "s", description = "extra lab seconds after each dimmer change" },
    load_timeout_s = { type = "number", default = 600, min = 0, max = 86400, unit = "s",
                       description = "how long to wait for the operator to confirm the chart and aim the meter" },
    keep = { type = "array", items = "string", values = { "average", "raw", "tiff16", "tiff8", "jpeg", "preview" },
             default = { "preview" }, max_items = 6, description = "frames kept in the image store per photograph" },
  },
  run = function(p)
    if #p.shutter_s ~= #p.levels then
      error({ class = "bad_parameter", message = string.format("%d levels but %d exposure times", #p.levels, #p.shutter_s),
              hint = "give one shutter_s per dimmer level (Table 7: 1/30, 1/15, 1/8, 1/4 s for 100, 50, 25, 15 %)" })
    end
    local dark = dark_border_ids()
    local reference
    if p.reference_run ~= "" then
      local ref = lab.runs.chart_reference(p.reference_run)
      if ref.chart ~= "sg" then error(string.format("reference_run %s read a %s chart, not the SG", p.reference_run, ref.chart)) end
      reference = { ids = ref.ids, XYZ = ref.XYZ }
    end
    local a = lab.operator.request {
      action = "load_chart", prompt = "Put the ColorChecker SG in the cabinet in front of the camera " .. p.camera .. ", facing it",
      options = { "loaded", "cancel" }, default = "loaded", timeout_s = p.load_timeout_s, details = { chart = "sg", where = "cabinet" },
    }
    if a.answer == "cancel" then error("the operator cancelled") end
    local aim = lab.operator.request {
      action = "aim_meter", prompt = "Aim the LS-110 at the cabinet floor beside the chart (spot row 4, column 5)",
      options = { "aimed", "skip" }, default = "aimed", timeout_s = p.load_timeout_s, details = { row = 3, col = 4 },
    }
    lab.log("meter: " .. aim.answer)
    lab.lamps.select(p.lamp)
    local out = { lamp = p.lamp, camera = p.camera, aperture_f = p.aperture_f, frames = p.frames, dark_ids = dark, levels = {} }
    for k, level in ipairs(p.levels) do
      lab.progress((k - 1) / #p.levels, string.format("%g %%", level))
      lab.dimmer.set(level, { settle_s = p.settle_s })
      local stable = lab.wait_stable()
      lab.camera.configure { camera = p.camera, shutter_s = p.shutter_s[k], aperture_f = p.aperture_f }
      local shot = lab.camera.photograph_chart { frames = p.frames, chart = "sg", formats = p.formats, camera = p.camera,
                                                 reference = reference, keep = p.keep }
      local key = string.format("D%g", level)
      local formats = {}
      local entry = { level = level, shutter_s = p.shutter_s[k], aperture_f = p.aperture_f, luminance = stable.luminance, intervals = {} }
      for _, format in ipairs(p.formats) do
        local f = shot.formats[format]
        local index = {}
        for i, id in ipairs(f.ids) do index[id] = i end
        local lo, hi = { math.huge, math.huge, math.huge }, { -math.huge, -math.huge, -math.huge }
        local unit = format == "raw" and "DN above black" or (f.bits == 8 and "8-bit code" or "16-bit code")
        for _, id in ipairs(dark) do
          local v = f.values[index[id]]
          for c = 1, 3 do
            lo[c] = math.min(lo[c], v[c])
            hi[c] = math.max(hi[c], v[c])
          end
          lab.record(string.format("dark/%s/%s/%s", format, key, id), {
            quantity = "camera_rgb", value = v[2], unit = unit, instrument = shot.instrument,
            data = { id = id, format = format, level = level, rgb = v },
          })
        end
        local interval = { hi[1] - lo[1], hi[2] - lo[2], hi[3] - lo[3] }
        lab.record(string.format("interval/%s/%s", format, key), {
          quantity = "interval_length", value = math.max(interval[1], interval[2], interval[3]), unit = unit,
          instrument = shot.instrument,
          data = { format = format, level = level, rgb = interval, min = lo, max = hi, ids = dark },
        })
        formats[format] = { ids = f.ids, values = f.values, bits = f.bits, confidence = f.confidence, corners = f.corners,
                            files = f.files }
        entry.intervals[format] = interval
      end
      lab.record("exposure/" .. key, {
        quantity = "shutter_s", value = p.shutter_s[k], unit = "s", instrument = shot.instrument,
        data = { level = level, shutter_s = p.shutter_s[k], aperture_f = p.aperture_f, frames = p.frames, lamp = p.lamp,
                 luminance = stable.luminance, luminance_unit = "cd/m²", formats = formats },
      })
      lab.log(string.format("%g %%: 1/%.0f s at f/%.1f, %.1f cd/m²", level, 1 / p.shutter_s[k], p.aperture_f, stable.luminance))
      out.levels[#out.levels + 1] = entry
    end
    -- Leave the camera as the dissertation chose (the first level's settings) and the cabinet at full light.
    lab.camera.configure { camera = p.camera, shutter_s = p.shutter_s[1], aperture_f = p.aperture_f }
    lab.dimmer.set(100)
    lab.progress(1, "done")
    return out
  end,
}
