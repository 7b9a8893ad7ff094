// The generated JSON Schema: checked in as docs/schema.json and kept true by this test.
// Run with SAFECASS_UPDATE_GOLDEN=1 to rewrite docs/schema.json.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "safecass/json/read.hpp"
#include "spec_test_support.hpp"

namespace safecass::spec {
namespace {

TEST(SpecSchema, CheckedInFileEqualsTheGeneratedSchema) {
  const std::string schema = json_schema(builtin_registry());
  const char* update = std::getenv("SAFECASS_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream("docs/schema.json", std::ios::binary) << schema;
    GTEST_SKIP() << "rewrote docs/schema.json";
  }
  EXPECT_EQ(read_text("docs/schema.json"), schema) << "docs/schema.json is stale: run `safecass schema > "
                                                      "docs/schema.json` (or this test with SAFECASS_UPDATE_GOLDEN=1)";
}

TEST(SpecSchema, IsDeterministicJsonOfDraft2020_12) {
  const std::string schema = json_schema(builtin_registry());
  EXPECT_EQ(schema, json_schema(builtin_registry()));
  const json::JsonParse p = json::parse_json(schema);
  ASSERT_TRUE(p.value) << p.error->message;
  EXPECT_EQ(p.value->find("$schema")->string, "https://json-schema.org/draft/2020-12/schema");
  const json::JsonValue* defs = p.value->find("$defs");
  ASSERT_NE(defs, nullptr);
  for (const char* def :
       {"system", "component", "include", "interfaces", "signal", "event", "filter", "pipeline", "target", "service",
        "dependency", "connection", "coordinators", "component_entry", "filter_entry"}) {
    EXPECT_NE(defs->find(def), nullptr) << def;
  }
}

TEST(SpecSchema, HasAnArgumentSchemaForEveryFilterTypeAndEveryNameOfIt) {
  const json::JsonParse p = json::parse_json(json_schema(builtin_registry()));
  ASSERT_TRUE(p.value);
  const json::JsonValue* defs = p.value->find("$defs");
  for (const FilterManifest* m : builtin_registry().manifests()) {
    const json::JsonValue* argument = defs->find("argument_" + m->type);
    ASSERT_NE(argument, nullptr) << m->type;
    EXPECT_EQ(argument->find("additionalProperties")->boolean, false);
    // Every parameter, and every other name of one (ChangeDetection's 2016 `event`).
    EXPECT_EQ(argument->find("properties")->object.size(), m->params.size() + m->aliases.size()) << m->type;
    for (const auto& [alias, param] : m->aliases)
      EXPECT_NE(argument->find("properties")->find(alias), nullptr) << alias;
  }
  const json::JsonValue* names = defs->find("filter")->find("properties")->find("class_name")->find("enum");
  ASSERT_NE(names, nullptr);
  std::vector<std::string> all;
  for (const json::JsonValue& n : names->array) all.push_back(n.string);
  EXPECT_THAT(all, ::testing::IsSupersetOf({"Threshold", "FilterThreshold", "Persistence", "Heartbeat", "Period",
                                            "TrendVel", "FilterTrendVel"}));
  const json::JsonValue* threshold = defs->find("argument_Threshold")->find("properties")->find("direction");
  EXPECT_EQ(threshold->find("default")->string, "above");
  const json::JsonValue* severity = defs->find("event")->find("properties")->find("severity");
  EXPECT_EQ(severity->find("minimum")->number, 1);
  EXPECT_EQ(severity->find("maximum")->number, 255);
}

TEST(SpecSchema, IncludesUserFilterTypes) {
  FilterRegistry registry;
  register_builtin_filters(registry);
  FilterManifest m;
  m.doc = "a user type";
  m.params = {ParamSpec::signal("input_signal", "what to read"), ParamSpec::number("gain", "how much", 2.0, 0, 10)};
  m.inputs = {"input_signal"};
  ASSERT_TRUE(registry.add("Gain", m, [](FilterInit) -> std::unique_ptr<Filter> { return nullptr; }));
  const std::string schema = json_schema(registry);
  EXPECT_THAT(schema, ::testing::HasSubstr("\"argument_Gain\""));
  EXPECT_THAT(schema, ::testing::HasSubstr("\"description\": \"Gain: a user type\""));
}

}  // namespace
}  // namespace safecass::spec
