-- Light-cabinet uniformity (dissertation §6.2, figs. 36–46, Tables 3–6): the LS-110 at every spot of
-- the floor's left half (8 × 10; the cabinet is symmetric) under each lamp and dimmer level, then the
-- analyses: luminance map, window standard deviations for a chart of the SG's border size, the best
-- placement, dimmer proportionality and the lamps compared.
--
-- On a real bench the meter is aimed by hand: the script asks once per spot (spot-major) and the DMX
-- widget runs the lamps and the dimmer. Spot-major needs the fewest operator moves, lamp-major the
-- fewest lamp warm-ups; `colorlab run --dry-run` shows what each costs. Lamps and dimmer levels are
-- visited in alternating order, so the lamp lit at the end of one spot is the first at the next and
-- need not warm up again.
--
-- A lamp that drifts: at each spot a lamp's levels are bracketed by a second reading at its first level
-- (drift_check), which the lab holds to the first; a light that moved by more than the lab's drift
-- tolerance suspends the execution until it is stable again. A lamp's readings at a spot are recorded
-- only once the bracket closed: when the lab had to wait for the light meanwhile (the reading comes back
-- with `resumed_after`), they are taken again, and the change is listed in the result's
-- `light_changes`, so maps measured before and after a lamp settled at a new level are not mixed silently.
local function grid_key(lamp, level, r, c)
  return string.format("L/%s/D%g/r%dc%d", lamp, level, r, c)
end

local function reversed(list)
  local out = {}
  for i = #list, 1, -1 do out[#out + 1] = list[i] end
  return out
end

return {
  description = "Cabinet uniformity (§6.2): LS-110 luminance at the floor's left-half spots under each lamp and dimmer level, with the §6.2 analyses",
  needs = { "luminance_meter", "lamps", "dimmer" },
  parameters = {
    rows = { type = "integer", default = 8, min = 1, max = 8, unit = "spots",
             description = "grid rows, from the front (the cabinet floor has 8)" },
    cols = { type = "integer", default = 10, min = 1, max = 10, unit = "spots",
             description = "grid columns of the left half, from the left wall (the half has 10)" },
    lamps = { type = "array", items = "string", default = { "D65", "TL84", "CWF" }, min_items = 1, max_items = 5,
              description = "lamps to measure, by their names in the lamp map" },
    dimmer_levels = { type = "array", items = "number", default = { 100, 50, 25, 15 }, min = 1, max = 100,
                      min_items = 1, max_items = 10, unit = "%", description = "dimmer levels to measure" },
    order = { type = "string", values = { "spot-major", "lamp-major" }, default = "spot-major",
              description = "spot-major: one operator move per spot; lamp-major: one warm-up per lamp" },
    readings = { type = "integer", default = 1, min = 1, max = 25, unit = "readings",
                 description = "LS-110 readings averaged per spot, lamp and level" },
    settle_s = { type = "number", default = 5, min = 0, max = 600, unit = "s",
                 description = "settling after each dimmer change (lab seconds)" },
    aim_timeout_s = { type = "number", default = 1800, min = 0, max = 86400, unit = "s",
                      description = "how long to wait for the operator to aim the meter before skipping the spot" },
    drift_check = { type = "boolean", default = true,
                    description = "read each lamp's first level again after its other levels at a spot, so a drifting lamp suspends the run and the spot is read again" },
  },
  run = function(p)
    local spots = {}
    for r = 0, p.rows - 1 do
      -- Back and forth along the rows: the shortest walk for whoever aims the meter.
      local first, last, step = 0, p.cols - 1, 1
      if r % 2 == 1 then first, last, step = p.cols - 1, 0, -1 end
      for c = first, last, step do spots[#spots + 1] = { r = r, c = c } end
    end
    local total = #spots * #p.lamps * #p.dimmer_levels
    local done, recorded, skipped, warmups, aims = 0, 0, 0, 0, 0
    local values = {}   -- [lamp][level][r][c] = cd/m²
    local lit = nil

    local function aim(spot)
      aims = aims + 1
      local a = lab.operator.request {
        action = "aim_meter",
        prompt = string.format("Aim the LS-110 at floor spot row %d, column %d (row 1 at the front, column 1 at the left wall)",
                               spot.r + 1, spot.c + 1),
        options = { "aimed", "skip" }, default = "skip", timeout_s = p.aim_timeout_s,
        details = { row = spot.r, col = spot.c },
      }
      return a.answer == "aimed"
    end

    local function light(lamp, level)
      if lit ~= lamp then
        lab.lamps.select(lamp)
        lab.dimmer.set(level, { settle_s = p.settle_s })
        lab.wait_stable()
        warmups = warmups + 1
        lit = lamp
      end
    end

    local light_changes = {}

    -- One level: the dimmer, then the readings. Returns them and what the lab reported of a suspension.
    local function read_level(level)
      lab.dimmer.set(level, { settle_s = p.settle_s })
      local raw, instrument, resumed = {}, nil, nil
      for i = 1, p.readings do
        local m = lab.meter.measure()
        raw[#raw + 1] = m.luminance
        instrument = m.instrument
        resumed = m.resumed_after or resumed
      end
      return raw, instrument, resumed
    end

    -- A lamp's levels at a spot, bracketed by its first level read again; read anew (at most three times)
    -- when the lab waited for the light in between, then recorded.
    local function measure(spot, lamp, levels)
      local taken
      for attempt = 1, 3 do
        taken = {}
        local resumed = nil
        for _, level in ipairs(levels) do
          local raw, instrument, r = read_level(level)
          taken[#taken + 1] = { level = level, raw = raw, instrument = instrument }
          resumed = r or resumed
        end
        if p.drift_check and #levels > 1 then
          local _, _, r = read_level(levels[1])
          resumed = r or resumed
        end
        if not resumed then break end
        light_changes[#light_changes + 1] = {
          lamp = lamp, row = spot.r, col = spot.c, attempt = attempt, cause = resumed.cause,
          dimmer_percent = resumed.dimmer_percent, change_pct = resumed.change_pct,
          level_before = resumed.level_before, stable_level = resumed.stable_level,
        }
      end
      for _, t in ipairs(taken) do
        local sum = 0
        for _, v in ipairs(t.raw) do sum = sum + v end
        local mean = sum / #t.raw
        lab.record(grid_key(lamp, t.level, spot.r, spot.c), {
          quantity = "luminance", value = mean, unit = "cd/m2", instrument = t.instrument,
          data = { row = spot.r, col = spot.c, lamp = lamp, dimmer_percent = t.level, readings = t.raw },
        })
        values[lamp] = values[lamp] or {}
        values[lamp][t.level] = values[lamp][t.level] or {}
        values[lamp][t.level][spot.r] = values[lamp][t.level][spot.r] or {}
        values[lamp][t.level][spot.r][spot.c] = mean
        done = done + 1
        recorded = recorded + 1
        lab.progress(done / total, string.format("%s %g%% row %d col %d", lamp, t.level, spot.r + 1, spot.c + 1))
      end
    end

    if p.order == "spot-major" then
      for k, spot in ipairs(spots) do
        if aim(spot) then
          local lamps = (k % 2 == 1) and p.lamps or reversed(p.lamps)
          for _, lamp in ipairs(lamps) do
            local levels = p.dimmer_levels
            if lit == lamp then levels = reversed(levels) end
            light(lamp, levels[1])
            measure(spot, lamp, levels)
          end
        else
          skipped = skipped + 1
          done = done + #p.lamps * #p.dimmer_levels
        end
      end
    else
      for _, lamp in ipairs(p.lamps) do
        light(lamp, p.dimmer_levels[1])
        for k, spot in ipairs(spots) do
          if aim(spot) then
            local levels = (k % 2 == 1) and p.dimmer_levels or reversed(p.dimmer_levels)
            measure(spot, lamp, levels)
          else
            skipped = skipped + 1
            done = done + #p.dimmer_levels
          end
        end
      end
    end

    -- §6.2 analyses on every complete grid.
    lab.progress(1.0, "analysing")
    local window = { window_rows = math.min(4, p.rows), window_cols = math.min(5, p.cols) }
    local function grid_of(lamp, level)
      local g = {}
      for r = 0, p.rows - 1 do
        local row = {}
        for c = 0, p.cols - 1 do
          local v = values[lamp] and values[lamp][level] and values[lamp][level][r] and values[lamp][level][r][c]
          if v == nil then return nil end
          row[#row + 1] = v
        end
        g[#g + 1] = row
      end
      return g
    end
    local top = p.dimmer_levels[1]
    for _, level in ipairs(p.dimmer_levels) do if level > top then top = level end end
    local maps, results, dimmer, incomplete = {}, {}, {}, {}
    local full_grids, full_names = {}, {}
    for _, lamp in ipairs(p.lamps) do
      maps[lamp] = {}
      results[lamp] = {}
      local reference = nil
      for _, level in ipairs(p.dimmer_levels) do
        local g = grid_of(lamp, level)
        if g then
          local u = lab.analysis.uniformity(g, window)
          results[lamp][tostring(level)] = u
          maps[lamp][tostring(level)] = {
            grid = g, min = u.min, max = u.max, best = u.best, window_stdev = u.window_stdev,
          }
          if level == top then
            reference = u
            full_grids[#full_grids + 1] = g
            full_names[#full_names + 1] = lamp
          end
        else
          incomplete[#incomplete + 1] = string.format("%s at %g%%", lamp, level)
        end
      end
      if reference then
        dimmer[lamp] = {}
        for _, level in ipairs(p.dimmer_levels) do
          local low = results[lamp][tostring(level)]
          if level ~= top and low then
            local d = lab.analysis.dimmer_proportionality(reference.difference, low.difference, level / top)
            dimmer[lamp][tostring(level)] = { max_abs_error = d.max_abs_error, error = d.error }
          end
        end
      end
    end
    local lamps_compared = #full_grids > 0 and lab.analysis.compare_lamps(full_names, full_grids, window) or {}
    return {
      order = p.order, rows = p.rows, cols = p.cols, unit = "cd/m2",
      grid_values = recorded, spots_skipped = skipped, operator_aims = aims, lamp_warmups = warmups,
      window = window, uniformity = maps, dimmer_proportionality = dimmer, lamps = lamps_compared,
      incomplete = incomplete, light_changes = light_changes,
    }
  end,
}
