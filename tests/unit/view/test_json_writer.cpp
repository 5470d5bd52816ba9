#include "view/json_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using meshnav::view::JsonWriter;

TEST(JsonWriter, NestsAndPlacesCommas) {
  JsonWriter w;
  w.beginObject().field("t", 1.5).key("ids").beginArray().integer(3).integer(4).endArray();
  w.key("o").beginObject().field("ok", true).field("name", std::string("a")).endObject();
  w.key("e").beginArray().endArray().endObject();
  EXPECT_EQ(w.str(), R"({"t":1.5,"ids":[3,4],"o":{"ok":true,"name":"a"},"e":[]})");
}

TEST(JsonWriter, NonFiniteNumbersAreNull) {
  JsonWriter w;
  w.beginArray().number(std::nan("")).number(std::numeric_limits<double>::infinity()).number(-2.25).endArray();
  EXPECT_EQ(w.str(), "[null,null,-2.25]");
}

TEST(JsonWriter, EscapesStrings) {
  EXPECT_EQ(JsonWriter::quoted("a\"b\\c\nd\x01"), "\"a\\\"b\\\\c\\nd\\u0001\"");
  EXPECT_EQ(JsonWriter::quoted("σ [°]"), "\"σ [°]\"");
}
