-- §6.1.3, Table 2: noise against the number of averaged frames. N frames of a uniform region
-- (default 25); the spatial standard deviation of the average of the first 1, 2, 4, 8, 16, 25
-- frames, per CFA channel. Noise falls as 1/sqrt(N) until only the fixed pattern is left, which
-- tells the lab how many frames are worth taking.
return {
  description = "Noise vs number of averaged frames (dissertation §6.1.3, Table 2) on a region of a camera image",
  needs = { "camera" },
  parameters = {
    frames = { type = "integer", default = 25, min = 2, max = 256, unit = "frames",
               description = "frames to capture; averages of the first 1, 2, 4, 8, 16, 25 … are analysed" },
    region = { type = "array", items = "integer", default = {}, max_items = 4, min = 0, unit = "px",
               description = "[x, y, width, height] in visible pixels; empty = the most uniform mid-level 32×32 window" },
    exposure_us = { type = "number", default = nil, min = 1, max = 10000000, unit = "µs",
                    description = "exposure time of a GenICam camera; unset = as configured" },
    keep = { type = "array", items = "string", values = { "average", "raw", "preview" }, default = { "average", "raw", "preview" },
             max_items = 3, description = "frames kept in the image store: the average (float array), the first frame as captured, a PNG preview" },
  },
  run = function(p)
    if #p.region ~= 0 and #p.region ~= 4 then error("region must be empty or {x, y, width, height}") end
    if p.exposure_us then lab.camera.configure({ exposure_us = p.exposure_us }) end
    lab.progress(0.0, "capturing")
    local t = lab.camera.capture({ frames = p.frames, region = p.region, keep = p.keep })
    lab.progress(0.9, "analysing")
    local table2 = {}
    for _, row in ipairs(t.rows) do
      lab.record(string.format("noise/N%d/%s", row.frames, row.channel),
                 { quantity = "pixel_stdev", value = row.stdev, unit = "DN", instrument = t.instrument,
                   data = { frames_averaged = row.frames, channel = row.channel, region = t.region } })
      table2[tostring(row.frames)] = table2[tostring(row.frames)] or {}
      table2[tostring(row.frames)][row.channel] = row.stdev
    end
    return { frames = t.frames, region = t.region, stdev_by_frames_averaged = table2, unit = t.unit }
  end,
}
