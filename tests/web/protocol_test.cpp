#include "tools/canmotion-web/protocol.hpp"

#include <gtest/gtest.h>

#include <string>

using namespace canmotion::web;

TEST(StatusLine, FieldsInOrderWithQuotedValues) {
  const std::string line =
      R"(axis=X type=CIP node=2 state=ServoControl drive="Operation enabled" cmd_pos=4.3125 )"
      R"(faults=- failure="node 2: transition 4 (x=1) timed out")";
  std::string err;
  const auto f = parse_fields(line, &err);
  ASSERT_TRUE(f) << err;
  ASSERT_EQ(f->size(), 8u);
  EXPECT_EQ((*f)[0], (std::pair<std::string, std::string>{"axis", "X"}));
  EXPECT_EQ((*f)[4].second, "Operation enabled");
  EXPECT_EQ((*f)[5].second, "4.3125");
  EXPECT_EQ((*f)[6].second, "-");
  EXPECT_EQ((*f)[7].first, "failure");
  EXPECT_EQ((*f)[7].second, "node 2: transition 4 (x=1) timed out");
}

TEST(StatusLine, MalformedLinesNameTheProblem) {
  std::string err;
  EXPECT_FALSE(parse_fields("axis=X bogus", &err));
  EXPECT_NE(err.find("column 8"), std::string::npos) << err;
  EXPECT_FALSE(parse_fields(R"(axis=X drive="Operation enabled)", &err));
  EXPECT_NE(err.find("unterminated quoted value of 'drive'"), std::string::npos) << err;
  EXPECT_FALSE(parse_fields("=1", &err));
}

TEST(StatusLine, EmptyValueAndEmptyLine) {
  std::string err;
  auto f = parse_fields("a= b=2", &err);
  ASSERT_TRUE(f) << err;
  ASSERT_EQ(f->size(), 2u);
  EXPECT_EQ((*f)[0].second, "");
  f = parse_fields("", &err);
  ASSERT_TRUE(f);
  EXPECT_TRUE(f->empty());
}

TEST(StatsLines, KeyValueMapAndBadLineReported) {
  std::string err;
  const auto m = parse_stats({"cycle=1200", "period_ms=1", "latency_p99_ns=23000", "garbage"}, &err);
  EXPECT_EQ(m.size(), 3u);
  EXPECT_EQ(m.at("latency_p99_ns"), "23000");
  EXPECT_NE(err.find("garbage"), std::string::npos);
}

TEST(Request, CommandObject) {
  std::string err;
  const auto r = parse_request(R"( {"type":"command", "verb":"MAJ", "axis":"X", "speed":-12.5e0, "hold":true} )", &err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->get("type"), "command");
  EXPECT_EQ(r->get("speed"), "-12.5e0");
  EXPECT_EQ(r->get("hold"), "true");
  EXPECT_EQ(r->get("missing"), "");
}

TEST(Request, EscapesDecoded) {
  std::string err;
  const auto r = parse_request(R"({"type":"watch","tag":"a\"b\\c\u0041"})", &err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->get("tag"), "a\"b\\cA");
}

TEST(Request, MalformedInputAnsweredWithReason) {
  const std::pair<std::string, std::string> cases[] = {
      {"", "expected '{'"},
      {"[1]", "expected '{'"},
      {R"({"type":"x")", "expected ',' or '}'"},
      {R"({"type":"x"} junk)", "trailing characters"},
      {R"({"type":{"a":1}})", "objects, arrays and null are not accepted"},
      {R"({"type":null})", "not accepted"},
      {R"({"type":"x","type":"y"})", "duplicate key 'type'"},
      {R"({"type":"x\q"})", "unknown escape"},
      {R"({"type":"x\u00e9"})", "non-ASCII"},
      {"{\"type\":\"a\nb\"}", "control character"},
      {R"({"type":12abc})", "bad number"},
      {R"({"verb":"MSO"})", "without key 'type'"},
      {R"({"type":"unterminated)", "unterminated string"},
      {R"({"type" "x"})", "expected ':' after key 'type'"},
  };
  for (const auto& [text, want] : cases) {
    std::string err;
    EXPECT_FALSE(parse_request(text, &err)) << text;
    EXPECT_NE(err.find(want), std::string::npos) << text << " -> " << err;
  }
}

TEST(Request, HugeAndManyKeysRefused) {
  std::string err;
  const std::string huge = R"({"type":")" + std::string(max_request_bytes, 'a') + R"("})";
  EXPECT_FALSE(parse_request(huge, &err));
  EXPECT_NE(err.find("too long"), std::string::npos) << err;
  std::string many = R"({"type":"x")";
  for (std::size_t k = 0; k < max_request_fields; ++k) many += ",\"k" + std::to_string(k) + "\":1";
  many += "}";
  EXPECT_FALSE(parse_request(many, &err));
  EXPECT_NE(err.find("too many keys"), std::string::npos) << err;
}

TEST(Request, EveryPrefixOfAValidRequestIsRejectedWithoutCrash) {
  const std::string good = R"({"type":"command","verb":"MAM","axis":"X","position":10.5})";
  for (std::size_t n = 0; n < good.size(); ++n) {
    std::string err;
    EXPECT_FALSE(parse_request(good.substr(0, n), &err)) << n;
    EXPECT_FALSE(err.empty()) << n;
  }
  std::string err;
  EXPECT_TRUE(parse_request(good, &err)) << err;
}

TEST(Json, StringEscapingAndFieldsRoundTrip) {
  EXPECT_EQ(json_string("a\"b\\c\n"), R"("a\"b\\c\u000a")");
  const Fields f{{"axis", "X"}, {"drive", "Operation enabled"}};
  const std::string j = fields_to_json(f);
  EXPECT_EQ(j, R"({"axis":"X","drive":"Operation enabled"})");
  std::string err;
  const auto r = parse_request(R"({"type":"status",)" + j.substr(1), &err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->get("drive"), "Operation enabled");
}
