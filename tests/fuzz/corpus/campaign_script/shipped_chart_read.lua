-- The chart's reference values (dissertation §6.1, appendix C): every patch of a ColorChecker SG (or
-- 24) on the SpectroScan T read by the Spectrolino — spectrum 380–730 nm, XYZ and L*a*b* (D50, 2°).
-- The table visits the patches in serpentine rows and recalibrates on its white tile as the driver
-- schedules it (before a row the calibration would not last through, and after a failed reading);
-- each patch is committed as it is read, so a crash loses at most the patch under the head.
-- characterize-camera takes its reference values from a run of this campaign.
return {
  description = "Chart reference values (§6.1, appendix C): every patch of the SG on the SpectroScan T, spectrum, XYZ and L*a*b* (D50, 2°)",
  needs = { "spectrophotometer", "table" },
  parameters = {
    chart = { type = "string", values = { "sg", "cc24" }, default = "sg", description = "the chart on the table" },
    first_x_mm = { type = "number", default = 31.2, min = 0, max = 310, unit = "mm",
                   description = "table X of the centre of the chart's first patch (A1 on an SG)" },
    first_y_mm = { type = "number", default = 29.45, min = 0, max = 230, unit = "mm",
                   description = "table Y of the centre of the chart's first patch" },
    pitch_mm = { type = "number", default = 19.0, min = 5, max = 60, unit = "mm",
                 description = "patch pitch on the chart (columns along X, rows along Y)" },
    confirm_load = { type = "boolean", default = true,
                     description = "ask the operator to confirm the chart is in place before reading" },
    load_timeout_s = { type = "number", default = 600, min = 0, max = 86400, unit = "s",
                       description = "how long to wait for that confirmation before reading anyway" },
  },
  run = function(p)
    local plan = lab.chart.plan { chart = p.chart, first_x_mm = p.first_x_mm, first_y_mm = p.first_y_mm,
                                  pitch_mm = p.pitch_mm }
    if p.confirm_load then
      local a = lab.operator.request {
        action = "load_chart",
        prompt = string.format("Place the %s on the SpectroScan T with the centre of its first patch at X %.1f mm, Y %.1f mm",
                               p.chart == "sg" and "ColorChecker SG" or "ColorChecker 24", p.first_x_mm, p.first_y_mm),
        options = { "loaded", "cancel" }, default = "loaded", timeout_s = p.load_timeout_s,
        details = { chart = p.chart },
      }
      if a.answer == "cancel" then error("the operator cancelled the chart read") end
    end
    lab.spectro.mode("reflectance")
    lab.table.hold_paper(true)
    local done, attempts, retried = 0, 0, 0
    for _, row in ipairs(plan.rows) do
      for k, patch in ipairs(row) do
        local r = lab.table.read_patch(patch.x_mm, patch.y_mm,
                                       { row_start = (k == 1), row_length = #row, index = patch.index })
        lab.record("patch/" .. patch.id, {
          quantity = "reflectance_spectrum", value = r.Lab[1], unit = "L*", instrument = r.instrument,
          data = { id = patch.id, index = patch.index, x_mm = patch.x_mm, y_mm = patch.y_mm,
                   first_nm = r.first_nm, step_nm = r.step_nm, values = r.values,
                   XYZ = r.XYZ, Lab = r.Lab, attempts = r.attempts,
                   illuminant = "D50", observer = "2deg" },
        })
        done = done + 1
        attempts = attempts + r.attempts
        if r.attempts > 1 then retried = retried + 1 end
        lab.progress(done / plan.patches, "patch " .. patch.id)
      end
    end
    lab.table.hold_paper(false)
    lab.table.home()
    return { chart = plan.chart, patches = done, patches_retried = retried, attempts = attempts,
             illuminant = "D50", observer = "2deg" }
  end,
}
