// The probe chain read back without a window (inspect/probe_chain.h): numbers printed with 4
// significant digits, field names split into section, label and unit, and the check that the
// parts add up to the sum, which fails when a part is left out.
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inspect/probe_chain.h"
#include "inspect/visualiser.h"

namespace voxlab {
namespace {

TEST(ProbeChain, FormatsFourSignificantDigits) {
  EXPECT_EQ(formatSignificant(0.123456789), "0.1235");
  EXPECT_EQ(formatSignificant(1234.5678), "1235");
  EXPECT_EQ(formatSignificant(123456.0), "1.235e+05");
  EXPECT_EQ(formatSignificant(0.0), "0");
  EXPECT_EQ(formatSignificant(-0.5), "-0.5");
  EXPECT_EQ(formatSignificant(2.0 / 3.0, 3), "0.667");
  EXPECT_EQ(formatRecordValue(nlohmann::json::array({0.1f, 1.0 / 3.0, 7})), "(0.1, 0.3333, 7)");
}

TEST(ProbeChain, SplitsFieldNames) {
  std::string section, label, unit;
  splitChainFieldName("direct: distance to the light [m]", section, label, unit);
  EXPECT_EQ(section, "direct");
  EXPECT_EQ(label, "distance to the light");
  EXPECT_EQ(unit, "m");
  splitChainFieldName("direct: n.l", section, label, unit);
  EXPECT_EQ(label, "n.l");
  EXPECT_EQ(unit, "");
  splitChainFieldName("alone", section, label, unit);
  EXPECT_EQ(section, "alone");
}

// A chain of three vec4 slots: two parts and their sum, the third part optional.
CapturedOutput chainOf(const std::vector<float>& slots, bool declareThirdPart) {
  CapturedOutput out;
  out.desc.name = "probe-chain";
  out.desc.kind = OutputKind::Buffer;
  out.desc.semantic = Semantic::ProbeChain;
  BufferLayout& l = out.desc.layout;
  l.stride = uint32_t(slots.size() * sizeof(float));
  l.fields = {{"direct: reflected [W/m^2/sr]", FieldType::Vec3, 0, FieldRole::Addend},
              {"indirect: weighted term [W/m^2/sr]", FieldType::Vec3, 16, FieldRole::Addend},
              {"composite: combined [W/m^2/sr]", FieldType::Vec3, 32, FieldRole::Sum}};
  if (declareThirdPart) l.fields.push_back({"indirect: second term [W/m^2/sr]", FieldType::Vec3, 48, FieldRole::Addend});
  out.recordCount = 1;
  out.records.resize(l.stride);
  std::memcpy(out.records.data(), slots.data(), l.stride);
  return out;
}

TEST(ProbeChain, PartsAddUpToTheSum) {
  // direct (1, 2, 3) + indirect (0.5, 0.25, 0) = (1.5, 2.25, 3); a second term (0.5, 0, 0) more.
  const std::vector<float> slots = {1, 2, 3, 0, 0.5f, 0.25f, 0, 0, 2.0f, 2.25f, 3, 0, 0.5f, 0, 0, 0};
  const CapturedOutput all = chainOf(slots, true);
  const ProbeChain chain = decodeProbeChain(all);
  ASSERT_EQ(chain.sections.size(), 4u);  // direct, indirect, composite, indirect again (declaration order)
  EXPECT_EQ(chain.sections[0].name, "direct");
  EXPECT_EQ(chain.sections[0].entries[0].unit, "W/m^2/sr");
  ProbeChainSum sum = sumProbeChain(chain);
  EXPECT_EQ(sum.error, "");
  EXPECT_LT(sum.worstRelative, 1e-6);
  const Visualiser& vis = visualiserFor(OutputKind::Buffer, Semantic::ProbeChain);
  EXPECT_EQ(vis.checkRecords(all).error, "");
  // Leave the second term out of the declaration: the parts no longer reach the sum.
  const CapturedOutput missing = chainOf(slots, false);
  sum = sumProbeChain(decodeProbeChain(missing));
  EXPECT_NEAR(sum.worstRelative, 0.5 / 2.0, 1e-6);
  EXPECT_NE(vis.checkRecords(missing).error.find("do not add up"), std::string::npos);
}

}  // namespace
}  // namespace voxlab
