-- The camera as an imaging luminance meter (issue 11): the whole cabinet floor from one averaged photograph per
-- lamp and dimmer level, calibrated against the LS-110 at a few spots, read out at the spots of §6.2's grid —
-- what cabinet-grid measures with 80 aims of the meter per lamp and level.
--
-- A lens passes less light away from its axis (vignetting, and the cos⁴ fall-off of a view as wide as the floor), so
-- one gain is not enough: lab.analysis.floor_luminance fits the flat field L = S · (c0 + c1·ρ² + c2·ρ⁴) on the
-- calibration spots the meter read under the same lamp and level (one term per spot up to `degree`). The first k
-- calibration spots and the first n frames give the cheaper settings the report compares (speed against accuracy):
-- every such variant is fitted here and stored with the level's photograph row.
--
-- On a real bench the operator takes the chart out of the cabinet and aims the camera at the floor (`aim_camera`),
-- measures the floor's corners on a first photograph and passes them as `corners`; on the simulated lab the simulator
-- does both (its floor view is the default). A lamp that drifts between the photograph and the meter's readings
-- (a reading that comes back with `resumed_after`) has the level photographed and read again, at most three times.
local function spot_of(name)
  local r, c = string.match(name, "^r(%d+)c(%d+)$")
  if not r then error("calibration spot '" .. name .. "' is not rRcC (0-based row and column, e.g. r3c4)") end
  return { r = tonumber(r), c = tonumber(c) }
end

local function key(prefix, lamp, level, spot)
  if spot then return string.format("%s/%s/D%g/r%dc%d", prefix, lamp, level, spot.r, spot.c) end
  return string.format("%s/%s/D%g", prefix, lamp, level)
end

return {
  description = "The camera as an imaging luminance meter: the cabinet floor from one averaged photograph per lamp and dimmer level, calibrated on a few LS-110 spots, at every spot of the §6.2 grid",
  needs = { "camera", "luminance_meter", "lamps", "dimmer" },
  parameters = {
    rows = { type = "integer", default = 8, min = 1, max = 8, unit = "spots",
             description = "grid rows reported, from the front (as cabinet-grid's)" },
    cols = { type = "integer", default = 10, min = 1, max = 20, unit = "spots",
             description = "grid columns reported, from the left wall (as cabinet-grid's left half)" },
    lamps = { type = "array", items = "string", default = { "D65", "TL84", "CWF" }, min_items = 1, max_items = 5,
              description = "lamps, by their names in the lamp map" },
    dimmer_levels = { type = "array", items = "number", default = { 100, 50, 25, 15 }, min = 1, max = 100,
                      min_items = 1, max_items = 10, unit = "%", description = "dimmer levels" },
    frames = { type = "integer", default = 8, min = 1, max = 256, unit = "frames",
               description = "frames averaged into each lamp and level's photograph" },
    calibration = { type = "array", items = "string", min_items = 1, max_items = 20,
                    default = { "r4c4", "r0c0", "r7c9", "r7c0", "r0c9" },
                    description = "LS-110 calibration spots rRcC on the 8 × 20 floor grid, in the order the report's cheaper settings take them (the first k)" },
    degree = { type = "integer", default = 2, min = 0, max = 4,
               description = "flat-field terms beyond the gain (ρ², ρ⁴, …), lowered to the calibration spots − 1" },
    corners = { type = "array", items = "number", min_items = 8, max_items = 8, min = -1, max = 2,
                default = { 0.03, 0.78875, 0.97, 0.78875, 0.87873, 0.26733, 0.12127, 0.26733 },
                description = "the floor's front-left, front-right, back-right, back-left corners in the photograph, x and y as fractions of its width and height (default: the simulated lab's floor view)" },
    spot_mm = { type = "number", default = 20, min = 1, max = 54, unit = "mm",
                description = "diameter of floor the camera averages at each spot" },
    settle_s = { type = "number", default = 5, min = 0, max = 600, unit = "s",
                 description = "settling after each dimmer change (lab seconds)" },
    aim_timeout_s = { type = "number", default = 1800, min = 0, max = 86400, unit = "s",
                      description = "how long to wait for the operator to aim the meter or the camera" },
    grid_run = { type = "string",
                 description = "the cabinet-grid run the report compares with (the campaign itself does not read it)" },
    keep = { type = "array", items = "string", default = { "preview" }, max_items = 3,
             description = "frames kept per photograph: average, raw, preview (an 8-megapixel average is 33 MB)" },
  },
  run = function(p)
    local grid, photographed, seen = {}, {}, {}
    for r = 0, p.rows - 1 do
      for c = 0, p.cols - 1 do
        grid[#grid + 1] = { r = r, c = c }
      end
    end
    local calibration = {}
    for _, name in ipairs(p.calibration) do calibration[#calibration + 1] = spot_of(name) end
    for _, list in ipairs({ grid, calibration }) do
      for _, s in ipairs(list) do
        local k = s.r .. "," .. s.c
        if not seen[k] then
          seen[k] = true
          photographed[#photographed + 1] = { s.r, s.c }
        end
      end
    end
    local corners = {}
    for i = 1, 8, 2 do corners[#corners + 1] = { p.corners[i], p.corners[i + 1] } end

    local camera = lab.operator.request {
      action = "aim_camera",
      prompt = "Take the chart out of the cabinet and aim the camera at the whole floor from the open front",
      options = { "aimed", "cancel" }, default = "cancel", timeout_s = p.aim_timeout_s, details = { view = "floor" },
    }
    if camera.answer ~= "aimed" then error("the camera was not aimed at the floor (" .. camera.by .. " answered " .. camera.answer .. ")") end

    local function aim(spot)
      local a = lab.operator.request {
        action = "aim_meter",
        prompt = string.format("Aim the LS-110 at floor spot row %d, column %d (row 1 at the front, column 1 at the left wall)",
                               spot.r + 1, spot.c + 1),
        options = { "aimed", "skip" }, default = "skip", timeout_s = p.aim_timeout_s,
        details = { row = spot.r, col = spot.c },
      }
      return a.answer == "aimed"
    end

    -- One level: the photograph, then the meter at each calibration spot, each timed by the lab's clock.
    local function take(level)
      lab.dimmer.set(level, { settle_s = p.settle_s })
      local t0 = lab.now()
      local photo = lab.camera.photograph_floor {
        frames = p.frames, corners = corners, spots = photographed, spot_mm = p.spot_mm, keep = p.keep,
      }
      local t1 = lab.now()
      local readings, resumed = {}, nil
      for _, spot in ipairs(calibration) do
        local ta = lab.now()
        if aim(spot) then
          local m = lab.meter.measure()
          resumed = m.resumed_after or resumed
          local tb = lab.now()
          readings[#readings + 1] = { row = spot.r, col = spot.c, luminance = m.luminance, instrument = m.instrument,
                                      seconds = tb.unix - ta.unix }
        end
      end
      return photo, t1.unix - t0.unix, readings, resumed
    end

    local total, done = #p.lamps * #p.dimmer_levels, 0
    local maps, fits, light_changes = {}, {}, {}
    -- The meter watches each lamp warm up at the first calibration spot; the lab holds readings at the other spots
    -- only to a cabinet gone nearly dark (a floor's corner under a fluorescent tube can be an eighth of its middle).
    for _, lamp in ipairs(p.lamps) do
      lab.lamps.select(lamp)
      lab.dimmer.set(p.dimmer_levels[1], { settle_s = p.settle_s })
      aim(calibration[1])
      lab.wait_stable()
      maps[lamp], fits[lamp] = {}, {}
      for _, level in ipairs(p.dimmer_levels) do
        lab.progress(done / total, string.format("%s %g%%", lamp, level))
        local photo, capture_s, readings, resumed
        for attempt = 1, 3 do
          photo, capture_s, readings, resumed = take(level)
          if not resumed then break end
          light_changes[#light_changes + 1] = { lamp = lamp, dimmer_percent = level, attempt = attempt,
                                                cause = resumed.cause, change_pct = resumed.change_pct }
        end
        if #readings == 0 then error(string.format("%s %g%%: no calibration spot was read", lamp, level)) end
        local spot_s = {}
        for _, m in ipairs(readings) do
          lab.record(key("C", lamp, level, { r = m.row, c = m.col }), {
            quantity = "luminance", value = m.luminance, unit = "cd/m2", instrument = m.instrument,
            data = { row = m.row, col = m.col, lamp = lamp, dimmer_percent = level, seconds = m.seconds },
          })
          spot_s[#spot_s + 1] = m.seconds
        end
        local fit = lab.analysis.floor_luminance(photo, readings, { degree = p.degree })
        -- The cheaper settings: the first k calibration spots, the first n frames.
        local variants = {}
        for k = 1, #readings do
          local first = {}
          for i = 1, k do first[i] = readings[i] end
          for _, n in ipairs(photo.subsets) do
            local v = lab.analysis.floor_luminance(photo, first, { degree = p.degree, subset = n })
            local values = {}
            for i = 1, #grid do values[i] = v.spots[i].luminance end
            variants[#variants + 1] = { spots = k, frames = n, degree = v.degree, luminance = values }
          end
        end
        local signals = {}
        for i, s in ipairs(photo.spots) do signals[i] = { row = s.row, col = s.col, px = s.px, pixels = s.pixels,
                                                           signal = s.signal, stdev = s.stdev } end
        lab.record(key("P", lamp, level), {
          quantity = "floor_photograph", value = capture_s, unit = "s", instrument = photo.instrument,
          data = { lamp = lamp, dimmer_percent = level, frames = p.frames, subsets = photo.subsets,
                   capture_s = capture_s, spot_s = spot_s, width = photo.width, height = photo.height,
                   corners_px = photo.corners_px, spot_mm = photo.spot_mm, degree = fit.degree,
                   coefficients = fit.coefficients, centre_px = fit.centre_px, radius_px = fit.radius_px,
                   calibration = fit.calibration, spots = signals, variants = variants, grid_rows = p.rows,
                   grid_cols = p.cols },
        })
        local map = {}
        for i, spot in ipairs(grid) do
          local s = fit.spots[i]
          lab.record(key("F", lamp, level, spot), {
            quantity = "luminance", value = s.luminance, unit = "cd/m2", instrument = photo.instrument,
            data = { row = spot.r, col = spot.c, lamp = lamp, dimmer_percent = level, gain = s.gain,
                     signal = photo.spots[i].signal[#photo.subsets] },
          })
          map[spot.r + 1] = map[spot.r + 1] or {}
          map[spot.r + 1][spot.c + 1] = s.luminance
        end
        maps[lamp][tostring(level)] = map
        fits[lamp][tostring(level)] = { degree = fit.degree, coefficients = fit.coefficients,
                                        calibration = fit.calibration, capture_s = capture_s }
        done = done + 1
      end
    end

    lab.progress(1.0, "putting the chart back")
    lab.operator.request {
      action = "aim_camera", prompt = "Put the chart back in the cabinet and aim the camera at it",
      options = { "done", "later" }, default = "later", timeout_s = p.aim_timeout_s, details = { view = "chart" },
    }
    return { lamps = p.lamps, dimmer_levels = p.dimmer_levels, frames = p.frames, calibration = p.calibration,
             maps = maps, fits = fits, light_changes = light_changes }
  end,
}
