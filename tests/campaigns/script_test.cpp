// A campaign script's declaration (parameters with type, unit, default and limits; the roles it
// needs) and the validation of a request's parameters against it, before anything moves.
#include <fstream>

#include <gtest/gtest.h>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/testing/temp_dir.hpp"
#include "engine_harness.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::campaigns::ScriptCatalogue;
using colorlab::testing::script_from;
using nlohmann::json;

namespace {

const char* kDeclared = R"lua(
return {
  description = "test",
  needs = { "luminance_meter" },
  parameters = {
    readings = { type = "integer", default = 3, min = 1, max = 10, unit = "readings", description = "how many" },
    lamp = { type = "string", default = "D65", values = { "D65", "TL84", "CWF" } },
    levels = { type = "array", items = "number", default = { 100, 50 }, min = 0, max = 100, max_items = 4 },
    fast = { type = "boolean", default = false },
    exposure = { type = "number", min = 1 },
  },
  run = function(p) end,
}
)lua";

ErrorClass class_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.cls();
  }
  return ErrorClass::internal;
}

}  // namespace

TEST(CampaignScript, DeclarationIsReadWithDefaultsUnitsAndLimits) {
  auto s = script_from("declared", kDeclared);
  EXPECT_EQ(s->description, "test");
  EXPECT_EQ(s->needs, std::vector<std::string>{"luminance_meter"});
  EXPECT_EQ(s->parameters["readings"]["default"], 3);
  EXPECT_EQ(s->parameters["readings"]["unit"], "readings");
  EXPECT_EQ(s->parameters["levels"]["default"], json::array({100, 50}));
  EXPECT_TRUE(s->parameters["exposure"]["default"].is_null());
  EXPECT_EQ(s->sha256.size(), 64u);

  json p = s->validate(json::object());
  EXPECT_EQ(p["readings"], 3);
  EXPECT_EQ(p["lamp"], "D65");
  EXPECT_TRUE(p["exposure"].is_null());
  p = s->validate({{"readings", 10}, {"lamp", "CWF"}, {"levels", {15}}, {"exposure", 2.5}});
  EXPECT_EQ(p["readings"], 10);
  EXPECT_EQ(p["levels"], json::array({15}));
}

TEST(CampaignScript, BadParametersAreRefusedNamingTheParameter) {
  auto s = script_from("declared", kDeclared);
  auto message = [&](const json& params) {
    try {
      s->validate(params);
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
      return e.info().message;
    }
    return std::string("accepted");
  };
  EXPECT_NE(message({{"readings", 11}}).find("params.readings"), std::string::npos);
  EXPECT_NE(message({{"readings", 0}}).find("params.readings"), std::string::npos);
  EXPECT_NE(message({{"readings", 2.5}}).find("integer"), std::string::npos);
  EXPECT_NE(message({{"readings", "3"}}).find("params.readings"), std::string::npos);
  EXPECT_NE(message({{"lamp", "UV"}}).find("one of"), std::string::npos);
  EXPECT_NE(message({{"levels", {10, 200}}}).find("params.levels[1]"), std::string::npos);
  EXPECT_NE(message({{"levels", {1, 2, 3, 4, 5}}}).find("at most"), std::string::npos);
  EXPECT_NE(message({{"fast", 1}}).find("true or false"), std::string::npos);
  EXPECT_NE(message({{"speed", 1}}).find("unknown parameter params.speed"), std::string::npos);
  EXPECT_EQ(message(json::array()), "params must be a JSON object");
}

TEST(CampaignScript, NonsenseDeclarationsAreScriptErrorsNamingTheFile) {
  auto cls = [](const std::string& src) { return class_of([&] { script_from("bad", src); }); };
  EXPECT_EQ(cls("return 42"), ErrorClass::script_error);
  EXPECT_EQ(cls("return { description = 'x' }"), ErrorClass::script_error);  // no run
  EXPECT_EQ(cls("return { needs = {'teleporter'}, run = function() end }"), ErrorClass::script_error);
  EXPECT_EQ(cls("return { parameters = { n = { type = 'complex' } }, run = function() end }"), ErrorClass::script_error);
  EXPECT_EQ(cls("return { parameters = { n = { type = 'integer', default = 50, max = 10 } }, run = function() end }"),
            ErrorClass::script_error);
  EXPECT_EQ(cls("return { run = function() end "), ErrorClass::script_error);  // syntax
  try {
    script_from("syntax", "return {\n run = function()\n  local x = = 1\n end }");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("syntax.lua:3:"), std::string::npos) << e.what();
  }
}

TEST(CampaignScript, TheShippedScriptsParse) {
  ScriptCatalogue catalogue({{std::filesystem::path(COLORLAB_SOURCE_DIR) / "campaigns" / "scripts", "shipped"}});
  EXPECT_TRUE(catalogue.broken().empty()) << catalogue.broken().front().error;
  ASSERT_TRUE(catalogue.find("luminance-spot"));
  ASSERT_TRUE(catalogue.find("frame-average"));
  EXPECT_EQ(catalogue.find("frame-average")->parameters["frames"]["default"], 25);
}

TEST(CampaignCatalogue, AScriptDroppedInAppearsAndAnEditIsPickedUp) {
  colorlab::testing::TempDir dir;
  ScriptCatalogue catalogue({{dir.path(), "lab"}});
  EXPECT_TRUE(catalogue.all().empty());
  std::ofstream(dir / "hello.lua") << "return { description = 'one', run = function() end }";
  catalogue.refresh();
  ASSERT_TRUE(catalogue.find("hello"));
  EXPECT_EQ(catalogue.find("hello")->description, "one");
  std::ofstream(dir / "hello.lua") << "return { description = 'two, edited', run = function() end }";
  catalogue.refresh();
  EXPECT_EQ(catalogue.find("hello")->description, "two, edited");
  std::ofstream(dir / "broken.lua") << "return {";
  catalogue.refresh();
  ASSERT_EQ(catalogue.broken().size(), 1u);
  EXPECT_NE(catalogue.broken()[0].error.find("broken.lua"), std::string::npos);
}
