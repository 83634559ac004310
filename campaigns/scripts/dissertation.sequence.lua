-- The dissertation's study (issue 11): every campaign of its tables and figures, in order, queued
-- together as one group of the night's queue. Data only. A step's `reference` names an earlier step
-- whose run goes into the given parameter when the step comes up (characterize-camera's reference_run
-- is the study's own chart-read). `covers` says what of the report the step is for (docs/reports.md,
-- "What it contains"). `small` is the reduced variant (tests, a first look): a 2 x 5 grid at two lamps
-- and levels, fewer frames; Tables 3-6 are then not compared cell by cell (the report says so).
-- colorlab run dissertation [--small] [-p STEP.KEY=VALUE] queues it and names the report the daemon makes of it
-- (GET /v1/queue/groups/{id}/report); colorlab study dissertation also writes that report to a file.
return {
  description = "the dissertation's whole study: chart reference, frame averaging, cabinet grid, the camera "
    .. "as a luminance meter, camera characterization and dimmer exposure; the group's report once it has ended",
  steps = {
    {
      name = "chart-read",
      campaign = "chart-read",
      -- §6.1: the SG's 140 patches on the SpectroScan T; the reference for chapter 7.
      params = { chart = "sg" },
      covers = "§6.1 chart reference (a*-b*, L* per patch); reference of characterize-camera",
    },
    {
      name = "frame-average",
      campaign = "frame-average",
      params = { frames = 25 },
      covers = "Table 2, fig. 34",
    },
    {
      name = "cabinet-grid",
      campaign = "cabinet-grid",
      -- The full 8 x 10 grid (Tables 3-6 are compared cell by cell only on it), three lamps x four levels:
      -- figs. 36-42 (D65 at 100/50/25/15 %), 43-46 (TL84, CWF at 100 and 50 %, and every other level),
      -- dimmer proportionality, lamps compared. Lamp-major: 3 lamp warm-ups instead of 161.
      params = { rows = 8, cols = 10, lamps = { "D65", "TL84", "CWF" }, dimmer_levels = { 100, 50, 25, 15 },
                 order = "lamp-major" },
      covers = "Tables 3-6, figs. 36-46, dimmer proportionality, lamps compared",
    },
    {
      name = "floor-luminance",
      campaign = "floor-luminance",
      -- The camera as an imaging luminance meter against that grid (issue 11): the same spots, lamps and levels
      -- from one photograph per lamp and level, calibrated on five LS-110 spots. Four frames: averaging more
      -- changes the floor's spot values by less than the LS-110's own noise (the report's Pareto chart shows it).
      params = { rows = 8, cols = 10, lamps = { "D65", "TL84", "CWF" }, dimmer_levels = { 100, 50, 25, 15 },
                 frames = 4 },
      reference = { param = "grid_run", step = "cabinet-grid" },
      covers = "the camera as an imaging luminance meter: agreement with the grid, time, Pareto chart",
    },
    {
      name = "characterize-camera",
      campaign = "characterize-camera",
      -- The three test cases of ch. 7 (8-bit TIFF, JPEG, 16-bit TIFF) and the raw for the black box.
      -- prior_exclude: the simulated camera is a 20D; its own curves must not be in the black box's prior.
      params = { chart = "sg", formats = { "raw", "tiff16", "tiff8", "jpeg" }, frames = 25, lamp = "D65",
                 prior_exclude = { "Canon_20D" } },
      reference = { param = "reference_run", step = "chart-read" },
      covers = "Tables 9-13, figs. 51-60, black box",
    },
    {
      name = "dimmer-exposure",
      campaign = "dimmer-exposure",
      -- §6.2's end: one SG photograph per dimmer level, exposure doubled as the light halves (Table 7), the dark
      -- border patches' interval lengths (Table 8). Last: it leaves the camera at 1/30 s, f/4 and the dimmer at 100 %.
      params = { levels = { 100, 50, 25, 15 } },
      reference = { param = "reference_run", step = "chart-read" },
      covers = "Tables 7, 8",
    },
  },
  small = {
    ["frame-average"] = { frames = 4 },
    ["cabinet-grid"] = { rows = 2, cols = 5, lamps = { "D65", "TL84" }, dimmer_levels = { 100, 50 }, settle_s = 0 },
    ["characterize-camera"] = { frames = 2 },
    ["floor-luminance"] = { rows = 2, cols = 5, lamps = { "D65", "TL84" }, dimmer_levels = { 100, 50 }, settle_s = 0,
                            frames = 2 },
    ["dimmer-exposure"] = { levels = { 100, 15 }, shutter_s = { 1 / 30, 1 / 4 } },
  },
}
