// `qem view RECORD`: a contraction record is shown as a chain of levels (GH97 §3), checked
// through the static export so no server or browser is needed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "qem/io.h"
#include "test_meshes.h"

using namespace qem;

TEST(CliViewRecord, RecordBecomesAChainFromTheOriginalToTheFinalMesh) {
  const std::string dir = test::temp_dir();
  save_mesh(dir + "/vr.ply", test::icosphere(4));  // 5120 faces
  const std::string cli = QEM_CLI_PATH;
  ASSERT_EQ(std::system((cli + " simplify " + dir + "/vr.ply " + dir + "/vr_out.ply --faces 100 -q --record " + dir +
                         "/vr.qemrec")
                            .c_str()),
            0);
  // The scene data is what is checked, not the page: a stub page keeps the test independent of
  // the npm build of web/ (QEM_WEB_DIR is the first place `qem view` looks).
  std::filesystem::create_directories(dir + "/stub_web");
  std::ofstream(dir + "/stub_web/index.html") << "<!doctype html>";
  std::ofstream(dir + "/stub_web/app.js") << "";
  const std::string env = "QEM_WEB_DIR=" + dir + "/stub_web ";
  ASSERT_EQ(std::system((env + cli + " view " + dir + "/vr.qemrec --export " + dir + "/vr_page > /dev/null").c_str()),
            0);
  std::ifstream f(dir + "/vr_page/data/scene.json");
  std::stringstream text;
  text << f.rdbuf();
  const std::string json = text.str();
  std::vector<long> faces;
  const std::regex re("\"faces\": *([0-9]+)");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator(); ++it)
    faces.push_back(std::stol((*it)[1]));
  ASSERT_GE(faces.size(), 3u) << json.substr(0, 400);
  EXPECT_EQ(faces.front(), 5120);
  EXPECT_EQ(faces.back(), 100);
  for (std::size_t i = 1; i < faces.size(); ++i) EXPECT_LT(faces[i], faces[i - 1]);
  // A record is not a mesh: it cannot be mixed with meshes.
  EXPECT_NE(std::system((env + cli + " view " + dir + "/vr.qemrec " + dir + "/vr.ply --compare --export " + dir +
                         "/vr_bad > /dev/null 2>&1")
                            .c_str()),
            0);
}
