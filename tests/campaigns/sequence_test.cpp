// Sequences (issue 11): NAME.sequence.lua read through the sandbox as data — steps with their
// parameters and references to earlier steps, the small variant's overrides; malformed ones are
// script errors naming the file and listed as broken; expand applies small, then per-step overrides,
// and refuses an unknown step or an override of a reference; the shipped dissertation parses and every
// step names a shipped campaign and only parameters it declares.
#include <fstream>

#include <gtest/gtest.h>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/sequence.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::campaigns::parse_campaign_sequence;
using colorlab::campaigns::ScriptCatalogue;
using nlohmann::json;

namespace {

const char* kPair = R"lua(
return {
  description = "a reference and what takes it",
  steps = {
    { name = "first", campaign = "luminance-spot", params = { readings = 3 }, covers = "the reference" },
    { name = "second", campaign = "takes-run", params = {}, reference = { param = "source_run", step = "first" } },
  },
  small = { first = { readings = 1 } },
}
)lua";

std::string error_of(const std::string& source) {
  try {
    parse_campaign_sequence("bad", source);
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::script_error) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << source;
  return "";
}

}  // namespace

TEST(CampaignSequence, StepsReferencesAndTheSmallVariantAreRead) {
  auto seq = parse_campaign_sequence("pair", kPair);
  EXPECT_EQ(seq.name, "pair");
  EXPECT_EQ(seq.description, "a reference and what takes it");
  ASSERT_EQ(seq.steps.size(), 2u);
  EXPECT_EQ(seq.steps[0].params, json({{"readings", 3}}));
  EXPECT_FALSE(seq.steps[0].reference_param);
  EXPECT_TRUE(seq.steps[1].params.is_object() && seq.steps[1].params.empty());
  EXPECT_EQ(seq.steps[1].reference_param, "source_run");
  EXPECT_EQ(seq.steps[1].reference_step, "first");
  auto j = seq.to_json();
  EXPECT_EQ(j["kind"], "sequence");
  EXPECT_EQ(j["steps"][1]["reference"], json({{"param", "source_run"}, {"step", "first"}}));
  EXPECT_EQ(j["small"]["first"]["readings"], 1);

  EXPECT_EQ(seq.expand(false, nullptr)[0].params["readings"], 3);
  EXPECT_EQ(seq.expand(true, nullptr)[0].params["readings"], 1);
  EXPECT_EQ(seq.expand(true, {{"first", {{"readings", 5}, {"interval_s", 2}}}})[0].params,
            json({{"readings", 5}, {"interval_s", 2}}))
      << "an override wins over the small variant";
  auto bad = [&](const json& overrides) {
    try {
      seq.expand(false, overrides);
    } catch (const Error& e) {
      return e.cls();
    }
    return ErrorClass::internal;
  };
  EXPECT_EQ(bad({{"third", {{"x", 1}}}}), ErrorClass::bad_parameter);
  EXPECT_EQ(bad({{"second", {{"source_run", "some-run"}}}}), ErrorClass::bad_parameter);
  EXPECT_EQ(bad({{"first", 3}}), ErrorClass::bad_parameter);
  EXPECT_EQ(bad(json::array()), ErrorClass::bad_parameter);
}

TEST(CampaignSequence, MalformedSequencesAreScriptErrorsNamingTheFile) {
  EXPECT_NE(error_of("return {").find("bad.sequence.lua"), std::string::npos);
  EXPECT_NE(error_of("return { steps = {} }").find("non-empty"), std::string::npos);
  EXPECT_NE(error_of("return { steps = { { campaign = 'x' } } }").find("`name`"), std::string::npos);
  EXPECT_NE(error_of("return { steps = { { name = 'a', campaign = 'x' }, { name = 'a', campaign = 'y' } } }")
                .find("two steps"),
            std::string::npos);
  EXPECT_NE(error_of("return { steps = { { name = 'a', campaign = 'x', reference = { param = 'p', step = 'b' } },"
                     " { name = 'b', campaign = 'y' } } }")
                .find("not an earlier step"),
            std::string::npos);
  EXPECT_NE(error_of("return { steps = { { name = 'a', campaign = 'x' }, { name = 'b', campaign = 'y', params = { p = 1 },"
                     " reference = { param = 'p', step = 'a' } } } }")
                .find("fills in"),
            std::string::npos);
  EXPECT_NE(error_of("return { steps = { { name = 'a', campaign = 'x' } }, small = { b = { n = 1 } } }").find("'b'"),
            std::string::npos);
  EXPECT_NE(error_of("return { steps = { { name = 'a', campaign = 'x', run = 1 } } }").find("unknown field"),
            std::string::npos);
  EXPECT_NE(error_of("return { steps = { { name = 'a', campaign = 'x' } }, extra = 1 }").find("unknown field"),
            std::string::npos);
  EXPECT_NE(error_of("while true do end").find("bad.sequence.lua"), std::string::npos) << "the budget ends a loop";
}

TEST(CampaignSequence, TheCatalogueListsSequencesApartAndABrokenOneWithItsError) {
  colorlab::testing::TempDir dir;
  std::ofstream(dir / "pair.sequence.lua") << kPair;
  std::ofstream(dir / "hello.lua") << "return { description = 'one', run = function() end }";
  std::ofstream(dir / "hello.sequence.lua") << "return { steps = { { name = 'a', campaign = 'hello' } } }";
  std::ofstream(dir / "broken.sequence.lua") << "return { steps = 3 }";
  ScriptCatalogue catalogue({{dir.path(), "lab"}});
  ASSERT_TRUE(catalogue.find_sequence("pair"));
  EXPECT_EQ(catalogue.find_sequence("pair")->origin, "lab");
  EXPECT_FALSE(catalogue.find("pair")) << "a sequence is not a campaign";
  EXPECT_FALSE(catalogue.find_sequence("hello")) << "a sequence may not take a campaign's name";
  ASSERT_TRUE(catalogue.find("hello"));
  EXPECT_EQ(catalogue.sequences().size(), 1u);
  ASSERT_EQ(catalogue.broken().size(), 2u);
  std::string errors = catalogue.broken()[0].error + " | " + catalogue.broken()[1].error;
  EXPECT_NE(errors.find("broken.sequence.lua"), std::string::npos) << errors;
  EXPECT_NE(errors.find("name of a campaign"), std::string::npos) << errors;
}

TEST(CampaignSequence, TheShippedDissertationNamesShippedCampaignsAndTheirParameters) {
  ScriptCatalogue catalogue({{std::filesystem::path(COLORLAB_SOURCE_DIR) / "campaigns" / "scripts", "shipped"}});
  EXPECT_TRUE(catalogue.broken().empty()) << catalogue.broken().front().error;
  auto seq = catalogue.find_sequence("dissertation");
  ASSERT_TRUE(seq);
  std::vector<std::string> names;
  for (const auto& small : {false, true}) {
    for (const auto& step : seq->expand(small, nullptr)) {
      auto script = catalogue.find(step.campaign);
      ASSERT_TRUE(script) << step.campaign;
      json params = step.params;
      if (step.reference_param) params[*step.reference_param] = "a-run";
      EXPECT_NO_THROW(script->validate(params)) << step.name << (small ? " (small)" : "") << ": " << params.dump();
      if (!small) names.push_back(step.name);
    }
  }
  EXPECT_EQ(names, (std::vector<std::string>{"chart-read", "frame-average", "cabinet-grid", "floor-luminance",
                                             "characterize-camera", "dimmer-exposure"}));
  EXPECT_EQ(seq->steps[4].reference_step, "chart-read");
  EXPECT_EQ(seq->steps[3].reference_param, "grid_run");
}
