// The jobs tier (app/): options schemas (defaults = the Options structs', validation, help/JSON
// generated from the one description) and the jobs chained on real files.
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/edit_job.h"
#include "app/edit_spec.h"
#include "app/retarget_job.h"
#include "app/transfer_job.h"
#include "io/asset.h"
#include "test_support.h"

namespace mm {
namespace {

using app::OptionValue;

template <class O>
void expect_schema_consistent(const app::OptionSchema<O>& schema) {
  const nlohmann::json j = nlohmann::json::parse(schema.json());
  ASSERT_EQ(j["job"], schema.job());
  ASSERT_EQ(j["options"].size(), schema.entries().size());
  const std::string help = schema.help();
  for (const auto& e : schema.entries()) {
    // Setting the default (as text, the CLI's way) is accepted.
    O o;
    EXPECT_TRUE(schema.set(o, e.info.name, OptionValue::of_text(e.info.default_text)).ok()) << e.info.name;
    // Every flag appears in --help with its default.
    const size_t at = help.find(e.info.cli_flag() + " ");
    ASSERT_NE(at, std::string::npos) << e.info.cli_flag();
    const std::string line = help.substr(at, help.find('\n', help.find(e.info.help, at)) - at);
    EXPECT_NE(line.find("(default " + (e.info.default_text.empty() ? std::string("none") : e.info.default_text)),
              std::string::npos)
        << line;
  }
  O o;
  const Status s = schema.set(o, "no_such_option", OptionValue::of_number(1));
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);
  EXPECT_NE(s.message.find("no_such_option"), std::string::npos);
}

TEST(OptionSchema, EveryJobIsConsistent) {
  expect_schema_consistent(app::transfer_options());
  expect_schema_consistent(app::transfer_part_options());
  expect_schema_consistent(app::edit_options());
  expect_schema_consistent(app::retarget_options());
}

TEST(OptionSchema, DefaultsAreTheOptionStructs) {
  // A default changed in an Options struct shows in the schema without touching it.
  const PoseTransferOptions t;
  const auto find = [](const auto& schema, const char* name) { return schema.find(name)->info.default_text; };
  EXPECT_EQ(find(app::transfer_options(), "cage_vertices"), std::to_string(t.cage.target_vertices));
  EXPECT_EQ(find(app::transfer_options(), "lambda1"), app::format_number(t.solver.lambda1));
  EXPECT_EQ(find(app::transfer_options(), "method"), "yin");
  const HarmonicRetargetOptions h;
  EXPECT_EQ(find(app::retarget_options(), "num_singularities"), std::to_string(h.map.singularities.count));
  EXPECT_EQ(find(app::retarget_options(), "w_smooth"), app::format_number(h.w_smooth));
  const LaplacianEditOptions e;
  EXPECT_EQ(find(app::edit_options(), "condition_threshold"), app::format_number(e.condition_threshold));
  EXPECT_EQ(find(app::edit_options(), "handle_basis"), e.handle_basis ? "true" : "false");
}

TEST(OptionSchema, SetsNestedFieldsAndRejectsBadValues) {
  const auto& schema = app::transfer_options();
  PoseTransferOptions o;
  ASSERT_TRUE(schema.set(o, "cage_vertices", OptionValue::of_text("300")).ok());
  EXPECT_EQ(o.cage.target_vertices, 300);
  ASSERT_TRUE(schema.set(o, "lambda2", OptionValue::of_number(0.25)).ok());
  EXPECT_EQ(o.solver.lambda2, 0.25);
  ASSERT_TRUE(schema.set(o, "method", OptionValue::of_text("levy")).ok());
  EXPECT_EQ(o.method, TransferMethod::Levy);
  ASSERT_TRUE(schema.set(o, "placement", OptionValue::of_text("source")).ok());
  EXPECT_EQ(o.placement, TransferPlacement::Source);
  // Kind, range and choice errors name the option; the value is not echoed in full.
  EXPECT_FALSE(schema.set(o, "cage_vertices", OptionValue::of_text("30.5")).ok());
  EXPECT_FALSE(schema.set(o, "cage_vertices", OptionValue::of_text("3")).ok());
  EXPECT_FALSE(schema.set(o, "lambda1", OptionValue::of_text("-1")).ok());
  EXPECT_FALSE(schema.set(o, "lambda1", OptionValue::of_text("nan")).ok());
  EXPECT_FALSE(schema.set(o, "lambda1", OptionValue::of_text("0.1x")).ok());
  EXPECT_FALSE(schema.set(o, "lambda1", OptionValue::of_boolean(true)).ok());
  const Status s = schema.set(o, "method", OptionValue::of_text(std::string(100000, 'y')));
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);
  EXPECT_NE(s.message.find("yin, kovnatsky or levy"), std::string::npos) << s.message;
  EXPECT_LT(s.message.size(), 200u);
  EXPECT_EQ(o.cage.target_vertices, 300);  // failed sets leave the value alone
  EXPECT_EQ(o.method, TransferMethod::Levy);
  // Booleans from JSON/JS or from CLI text.
  app::EditJobOptions e;
  ASSERT_TRUE(app::edit_options().set(e, "handle_basis", OptionValue::of_text("false")).ok());
  EXPECT_FALSE(e.editor.handle_basis);
  ASSERT_TRUE(app::edit_options().set(e, "handle_basis", OptionValue::of_boolean(true)).ok());
  EXPECT_TRUE(e.editor.handle_basis);
}

TEST(OptionSchema, FormatNumberRoundTrips) {
  for (double x : {0.05, 2e5, 1e-6, 0.001, 1.0 / 3.0, 260.0, -7.25}) {
    const std::string t = app::format_number(x);
    EXPECT_EQ(std::strtod(t.c_str(), nullptr), x) << t;
  }
  EXPECT_EQ(app::format_number(0.05), "0.05");
  EXPECT_EQ(app::format_number(200000), "200000");
}

TEST(EditSpecOptions, GoThroughTheEditSchema) {
  const Mesh bar = test::load_mesh("edit/bar.ply");
  const std::string spec = R"({"handles": [{"select": [0], "translate": [0, 0, 0.1]}],
                               "options": {"method": "naive", "coherence_rings": 1, "features": "scale"}})";
  EditSpecResult r = parse_edit_spec(spec, bar.V, bar.F);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.spec.options.method, EditMethod::NaiveLaplacian);
  EXPECT_EQ(r.spec.options.coherence_rings, 1);
  EXPECT_EQ(r.spec.features, FeatureSize::Scale);
  r = parse_edit_spec(R"({"handles": [{"select": [0]}], "options": {"coherence_rings": 7}})", bar.V, bar.F);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
  EXPECT_NE(r.status.message.find("coherence_rings"), std::string::npos) << r.status.message;
  r = parse_edit_spec(R"({"handles": [{"select": [0]}], "options": {"colour": 1}})", bar.V, bar.F);
  EXPECT_EQ(r.status.code, StatusCode::ParseError);
}

// The edit job chains load → edit → save; its output equals the editor run directly.
TEST(EditJob, FileChainEqualsTheEditor) {
  app::EditJobRequest req;
  req.files = {test::data_path("edit/bar.ply"), test::data_path("specs/bar_bend.json"),
               test::scratch_path("app_edit_bar_bend.ply")};
  const app::EditJobResult r = app::run_edit_job(req);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_TRUE(r.finalized);
  EXPECT_GT(r.handles, 0);
  EXPECT_EQ(r.inverted_faces, 0);

  const Mesh bar = test::load_mesh("edit/bar.ply");
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::read_file(req.files.spec, &bytes).ok());
  EditSpecResult sr = parse_edit_spec(std::string(bytes.begin(), bytes.end()), bar.V, bar.F);
  ASSERT_TRUE(sr.status.ok());
  LaplacianEditor editor;
  ASSERT_TRUE(editor.precompute(bar.V, bar.F, sr.spec.region, sr.spec.options).ok());
  ASSERT_TRUE(editor.drag(sr.spec.transforms).status.ok());
  const EditResult direct = editor.finalize(sr.spec.features);
  ASSERT_TRUE(direct.status.ok());
  const io::LoadResult written = io::load_asset(req.files.out);
  ASSERT_TRUE(written.status.ok()) << written.status.message;
  const Mesh out = written.asset.mesh();
  ASSERT_EQ(out.V.rows(), direct.V.rows());
  // PLY stores float32: equal to float precision.
  EXPECT_LT((out.V - direct.V).cwiseAbs().maxCoeff(), 1e-5 * (1 + direct.V.cwiseAbs().maxCoeff()));

  // An override (the CLI's flags) wins over the spec: naive editing changes the result.
  req.set_overrides = [](app::EditJobOptions& o) {
    return app::edit_options().set(o, "method", app::OptionValue::of_text("naive"));
  };
  req.files.out = test::scratch_path("app_edit_bar_bend_naive.ply");
  const app::EditJobResult n = app::run_edit_job(req);
  ASSERT_TRUE(n.status.ok()) << n.status.message;
  EXPECT_FALSE(n.finalized);
  EXPECT_GT(n.rigidity_error, r.rigidity_error);
}

TEST(EditJob, MissingFilesAreClearErrors) {
  app::EditJobRequest req;
  req.files = {test::data_path("edit/bar.ply"), test::data_path("specs/no_such_spec.json"),
               test::scratch_path("app_edit_never.ply")};
  const app::EditJobResult r = app::run_edit_job(req);
  EXPECT_EQ(r.status.code, StatusCode::IoError);
  EXPECT_FALSE(std::fopen(req.files.out.c_str(), "rb"));
}

}  // namespace
}  // namespace mm
