-- a campaign as docs/campaigns.md describes it
return {
  description = "one reading",
  needs = { "luminance_meter" },
  parameters = {
    readings = { type = "integer", default = 1, min = 1, max = 10, unit = "readings", description = "how many" },
    mode = { type = "string", values = { "a", "b" }, default = "a" },
    levels = { type = "array", items = "number", default = { 100, 50 }, min = 1, max = 100, min_items = 1, max_items = 4 },
    check = { type = "boolean", default = true },
  },
  limits = { memory_mib = 16, instruction_budget = 1e6 },
  run = function(p)
    for i = 1, p.readings do lab.record("spot/" .. i, lab.meter.measure()) end
  end,
}
