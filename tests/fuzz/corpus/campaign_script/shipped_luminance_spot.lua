-- Spot luminance with the LS-110: N readings of the spot the meter is aimed at, their mean and
-- standard deviation. The Quick start's default campaign.
return {
  description = "Spot luminance with the LS-110: N readings of the aimed spot, their mean and standard deviation",
  needs = { "luminance_meter" },
  parameters = {
    readings = { type = "integer", default = 1, min = 1, max = 1000, unit = "readings",
                 description = "how many readings to take" },
    interval_s = { type = "number", default = 0, min = 0, max = 3600, unit = "s",
                   description = "pause between readings (lab seconds)" },
  },
  run = function(p)
    local values = {}
    for i = 1, p.readings do
      local step = string.format("reading/%d", i - 1)
      lab.progress((i - 1) / p.readings, step)
      local r = lab.meter.measure()
      lab.record(step, { quantity = "luminance", value = r.luminance, unit = r.unit,
                         instrument = r.instrument, data = { raw = r.raw } })
      values[#values + 1] = r.luminance
      if p.interval_s > 0 and i < p.readings then lab.wait(p.interval_s) end
    end
    local s = lab.analysis.summarize(values)
    return { readings = s.count, mean = s.mean, stdev = s.stdev, unit = "cd/m2" }
  end,
}
