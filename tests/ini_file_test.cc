// carmen.ini reading: every syntax, section and limit rule, one test each.
// Expected values follow from the rules and the test files, worked out by hand.
// Sources, priorities and typed values: ini_file_values_test.cc.
#include "carmen_compat/ini_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ini_file_test_support.h"
#include "temp_dir.h"

namespace {

using namespace initest;

// ---------------------------------------------------------------------------
// Syntax (tests/data/ini/syntax.ini)

TEST(IniSyntax, HashStartsACommentAnywhere) {
  const ParamFile pf = ParamFile::load(path("syntax.ini"));
  // "[*]   # a comment after a section header" is still the [*] header.
  EXPECT_EQ(value_of(pf, "vasco_plain"), "1");
  // "vasco_comment 4# no space before the comment"
  EXPECT_EQ(value_of(pf, "vasco_comment"), "4");
  // "vasco_comment_only # the value is empty"
  EXPECT_TRUE(pf.has("vasco_comment_only"));
  EXPECT_EQ(value_of(pf, "vasco_comment_only"), "");
  // "vasco_a#b 5": the name is cut at '#', so it is vasco_a with no value.
  EXPECT_EQ(value_of(pf, "vasco_a"), "");
  EXPECT_EQ(line_of(pf, "vasco_a"), 12);
  EXPECT_FALSE(pf.has("vasco_a#b"));
}

TEST(IniSyntax, TrailingThenLeadingBlanksAreTrimmed) {
  const ParamFile pf = ParamFile::load(path("syntax.ini"));
  // "\tvasco_tabbed\t2\t" and "   vasco_spaced    3    "
  EXPECT_EQ(value_of(pf, "vasco_tabbed"), "2");
  EXPECT_EQ(line_of(pf, "vasco_tabbed"), 6);
  EXPECT_EQ(value_of(pf, "vasco_spaced"), "3");
  EXPECT_EQ(line_of(pf, "vasco_spaced"), 7);
  EXPECT_EQ(pf.find("vasco_spaced")->name, "vasco_spaced");
}

TEST(IniSyntax, TheRestOfTheLineIsTheValue) {
  const ParamFile pf = ParamFile::load(path("syntax.ini"));
  // "vasco_words the lab    floor\t(second) ": inner blanks stay as written.
  EXPECT_EQ(value_of(pf, "vasco_words"), "the lab    floor\t(second)");
  EXPECT_EQ(pf.get_string("vasco_words"), "the lab    floor\t(second)");
  const ParamFile one = ParamFile::parse("[*]\nlaser_dev \t /dev/tty S0 \n", "t.ini");
  EXPECT_EQ(value_of(one, "laser_dev"), "/dev/tty S0");
}

TEST(IniSyntax, NameWithoutValueIsKeptEmpty) {
  const ParamFile pf = ParamFile::load(path("syntax.ini"));
  ASSERT_TRUE(pf.has("vasco_empty"));
  EXPECT_EQ(value_of(pf, "vasco_empty"), "");
  EXPECT_EQ(pf.get_string("vasco_empty"), "");
}

TEST(IniSyntax, NameSplitsAtTheFirstUnderscore) {
  const ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ 0.55\n", "t.ini");
  const auto pv = pf.find("vasco_p_occ");
  ASSERT_TRUE(pv.has_value());
  EXPECT_EQ(pv->module(), "vasco");
  EXPECT_EQ(pv->variable(), "p_occ");
}

TEST(IniSyntax, NameWithoutModuleOrVariableIsDroppedWithAWarning) {
  const ParamFile pf = ParamFile::load(path("syntax.ini"));
  EXPECT_FALSE(pf.has("nounderscore"));
  EXPECT_FALSE(pf.has("_nomodule"));
  EXPECT_FALSE(pf.has("novariable_"));
  const std::string file = path("syntax.ini");
  const std::vector<std::string> expected = {
      file + ":13: 'nounderscore' is not module_variable; ignored",
      file + ":14: '_nomodule' is not module_variable; ignored",
      file + ":15: 'novariable_' is not module_variable; ignored",
  };
  EXPECT_EQ(warning_texts(pf), expected);
  ASSERT_EQ(pf.warnings().size(), 3u);
  EXPECT_EQ(pf.warnings()[0].file, file);
  EXPECT_EQ(pf.warnings()[0].line, 13);
}

TEST(IniSyntax, LookupIsCaseInsensitive) {
  const ParamFile pf = ParamFile::load(path("vasco_typo.ini"));
  // Written "VASCO_Range_Max 20" on line 5.
  EXPECT_EQ(value_of(pf, "vasco_range_max"), "20");
  EXPECT_EQ(value_of(pf, "VASCO_RANGE_MAX"), "20");
  EXPECT_EQ(pf.find("Vasco_Range_max")->name, "VASCO_Range_Max");
  EXPECT_EQ(pf.get_int("vasco_range_max"), 20);
}

TEST(IniSyntax, LaterDefinitionWins) {
  const ParamFile pf =
      ParamFile::parse("[*]\nvasco_border 1\nrobot_length 1\nVASCO_BORDER 2\n", "t.ini");
  EXPECT_EQ(value_of(pf, "vasco_border"), "2");
  EXPECT_EQ(line_of(pf, "vasco_border"), 4);
  EXPECT_EQ(pf.find("vasco_border")->name, "VASCO_BORDER");
}

TEST(IniSyntax, LaterDefinitionWinsAcrossSections) {
  // one_robot.ini: [*] robot_frontlaser_offset 0.0 (line 6), then
  // [Scout] robot_frontlaser_offset 0.25 (line 9). A robot section does not
  // outrank [*]; file order does:
  const ParamFile pf = ParamFile::load(path("one_robot.ini"));
  EXPECT_EQ(value_of(pf, "robot_frontlaser_offset"), "0.25");
  EXPECT_EQ(line_of(pf, "robot_frontlaser_offset"), 9);
  const ParamFile back = ParamFile::parse("[r]\nrobot_x 1\n[*]\nrobot_x 2\n", "t.ini");
  EXPECT_EQ(value_of(back, "robot_x"), "2");
}

TEST(IniSyntax, LinesBeforeTheFirstSectionAreIgnored) {
  // one_robot.ini line 2 says robot_length 9.9 before any section.
  const ParamFile pf = ParamFile::load(path("one_robot.ini"));
  EXPECT_EQ(value_of(pf, "robot_length"), "0.5");
  EXPECT_EQ(line_of(pf, "robot_length"), 5);
  EXPECT_EQ(warning_texts(pf), std::vector<std::string>{path("one_robot.ini") +
                                                        ":2: definition before the first "
                                                        "section ignored"});
}

TEST(IniSyntax, LastLineWithoutNewlineIsKept) {
  // CARMEN 0.7.4 loses "vasco_border 7": the file does not end in '\n'.
  const ParamFile pf = ParamFile::load(path("no_trailing_newline.ini"));
  EXPECT_EQ(pf.get_int("vasco_border"), 7);
  EXPECT_EQ(line_of(pf, "vasco_border"), 3);
  EXPECT_EQ(ParamFile::parse("[*]\na_b 1", "t.ini").get_int("a_b"), 1);
}

TEST(IniSyntax, CrLfLineEndsAreLineEnds) {
  const ParamFile pf = ParamFile::load(path("crlf.ini"));
  EXPECT_EQ(value_of(pf, "vasco_resolution"), "0.05");
  EXPECT_DOUBLE_EQ(pf.get_double("vasco_resolution"), 0.05);
  EXPECT_EQ(value_of(pf, "vasco_note"), "on the\tlab floor");
  EXPECT_EQ(line_of(pf, "vasco_note"), 3);
}

TEST(IniSyntax, LineOver2047CharactersIsAnError) {
  const std::string msg = error_of([] { ParamFile::load(path("long_line.ini")); });
  EXPECT_TRUE(contains(msg, path("long_line.ini") + ":3: line longer than 2047 characters"));

  // 2047 characters is the longest line allowed; the line end does not count.
  const std::string head = "vasco_note ";
  const std::string ok = head + std::string(2047 - head.size(), 'x');
  ASSERT_EQ(ok.size(), 2047u);
  const ParamFile pf = ParamFile::parse("[*]\n" + ok + "\r\n", "t.ini");
  EXPECT_EQ(pf.get_string("vasco_note").size(), 2047u - head.size());
  const std::string too_long = ok + "x";
  EXPECT_TRUE(contains(error_of([&] { ParamFile::parse("[*]\n" + too_long + "\n", "t.ini"); }),
                       "t.ini:2: line longer than 2047 characters"));
  // Lines are checked in every section, also in those that do not apply.
  EXPECT_TRUE(contains(
      error_of([&] { ParamFile::parse("[*]\n[other]\n" + too_long, "t.ini"); }), "t.ini:3: "));
}

TEST(IniSyntax, NameOver254CharactersIsAnError) {
  const std::string name254 = "vasco_" + std::string(254 - 6, 'n');
  const ParamFile pf = ParamFile::parse("[*]\n" + name254 + " 1\n", "t.ini");
  EXPECT_EQ(pf.get_int(name254), 1);
  EXPECT_TRUE(contains(error_of([&] { ParamFile::parse("[*]\n" + name254 + "n 1\n", "t.ini"); }),
                       "t.ini:2: parameter name longer than 254 characters"));
}

TEST(IniSyntax, MalformedSectionHeaders) {
  EXPECT_EQ(error_of([] { ParamFile::parse("[*]\na_b 1\n[scout\n", "t.ini"); }),
            "t.ini:3: section header without ']': [scout");
  EXPECT_EQ(error_of([] { ParamFile::parse("[ ]\n", "t.ini"); }), "t.ini:1: empty section name");
  const ParamFile pf = ParamFile::parse("[*] extra\na_b 1\n", "t.ini");
  EXPECT_EQ(value_of(pf, "a_b"), "1");
  EXPECT_EQ(warning_texts(pf),
            std::vector<std::string>{"t.ini:1: text after section header [*] ignored: extra"});
}

TEST(IniSyntax, NulByteIsAnError) {
  const std::string text = std::string("[*]\na_b 1\nc_d \0x\n", 17);
  EXPECT_EQ(error_of([&] { ParamFile::parse(text, "t.ini"); }),
            "t.ini:3: NUL byte: not a text parameter file");
}

TEST(IniFile, MissingFileIsAnErrorNamingIt) {
  const std::string missing = path("does_not_exist.ini");
  const std::string msg = error_of([&] { ParamFile::load(missing); });
  EXPECT_EQ(msg.rfind(missing + ": cannot open: ", 0), 0u) << msg;
  try {
    ParamFile::load(missing);
  } catch (const FileError &e) {
    EXPECT_EQ(e.file(), missing);
    EXPECT_EQ(e.line(), 0);
  }
}

TEST(IniFile, DirectoryIsAnError) {
  const std::string msg = error_of([] { ParamFile::load(kDir); });
  EXPECT_TRUE(contains(msg, kDir + ": is a directory, not a regular file")) << msg;
}

// ---------------------------------------------------------------------------
// Sections and robots

TEST(IniRobots, NoRobotSectionsOnlyStarAndExpertApply) {
  const ParamFile pf =
      ParamFile::parse("[*]\nrobot_length 0.5\n[expert]\nvasco_border 30\n", "t.ini");
  EXPECT_TRUE(pf.robots().empty());
  EXPECT_EQ(pf.selected_robot(), "");
  EXPECT_EQ(value_of(pf, "robot_length"), "0.5");
  EXPECT_EQ(value_of(pf, "vasco_border"), "30");
}

TEST(IniRobots, NoRobotSectionsButARobotRequestedIsAnError) {
  EXPECT_EQ(error_of([] { ParamFile::parse("[*]\nrobot_length 0.5\n", "t.ini", "scout"); }),
            "t.ini: no section [scout] for robot 'scout' (the file has no robot sections)");
}

TEST(IniRobots, OneRobotIsSelectedAutomatically) {
  const ParamFile pf = ParamFile::load(path("one_robot.ini"));
  EXPECT_EQ(pf.robots(), std::vector<std::string>{"Scout"});
  EXPECT_EQ(pf.selected_robot(), "Scout");
  EXPECT_DOUBLE_EQ(pf.get_double("robot_frontlaser_offset"), 0.25);
  // [*] applies before and after the robot section.
  EXPECT_DOUBLE_EQ(pf.get_double("robot_width"), 0.4);
}

TEST(IniRobots, SeveralRobotsWithoutOneChosenIsAnErrorListingThem) {
  const std::string file = path("several_robots.ini");
  EXPECT_EQ(error_of([&] { ParamFile::load(file); }),
            file + ": several robots (p2d8+, Scout, pioneer): the robot to use must be named");
}

TEST(IniRobots, ChosenRobotMatchesCaseInsensitively) {
  const ParamFile scout = ParamFile::load(path("several_robots.ini"), "SCOUT");
  EXPECT_EQ(scout.robots(), (std::vector<std::string>{"p2d8+", "Scout", "pioneer"}));
  EXPECT_EQ(scout.selected_robot(), "Scout");
  EXPECT_DOUBLE_EQ(scout.get_double("robot_frontlaser_offset"), 0.25);
  EXPECT_DOUBLE_EQ(scout.get_double("robot_length"), 0.5);   // from [*]
  EXPECT_DOUBLE_EQ(scout.get_double("robot_width"), 0.4);    // [pioneer]'s 0.45 does not apply
  EXPECT_EQ(line_of(scout, "robot_frontlaser_offset"), 12);

  const ParamFile p2 = ParamFile::load(path("several_robots.ini"), "p2d8+");
  EXPECT_DOUBLE_EQ(p2.get_double("robot_frontlaser_offset"), -0.04);
  EXPECT_DOUBLE_EQ(p2.get_double("robot_length"), 0.6);  // [p2d8+] comes after [*]

  const ParamFile pioneer = ParamFile::load(path("several_robots.ini"), "pioneer");
  EXPECT_DOUBLE_EQ(pioneer.get_double("robot_frontlaser_offset"), 0.1);
  EXPECT_DOUBLE_EQ(pioneer.get_double("robot_width"), 0.45);
}

TEST(IniRobots, RobotWithoutASectionIsAnError) {
  const std::string file = path("several_robots.ini");
  EXPECT_EQ(error_of([&] { ParamFile::load(file, "b21"); }),
            file + ": no section [b21] for robot 'b21' (robots: p2d8+, Scout, pioneer)");
}

TEST(IniRobots, RepeatedRobotSectionIsOneRobot) {
  const ParamFile pf =
      ParamFile::parse("[*]\n[scout]\nrobot_a 1\n[SCOUT]\nrobot_b 2\n", "t.ini");
  EXPECT_EQ(pf.robots(), std::vector<std::string>{"scout"});
  EXPECT_EQ(value_of(pf, "robot_a"), "1");
  EXPECT_EQ(value_of(pf, "robot_b"), "2");
}

TEST(IniRobots, SectionsThatDoNotApplyAreNotParsed) {
  // A bad name in another robot's section is neither stored nor warned about.
  const ParamFile pf =
      ParamFile::parse("[a]\nrobot_x 1\nbadname 2\n[b]\nrobot_x 3\n", "t.ini", "b");
  EXPECT_EQ(value_of(pf, "robot_x"), "3");
  EXPECT_TRUE(pf.warnings().empty());
}

TEST(IniExpert, ExpertSectionAppliesToAllRobotsAndMarksExpert) {
  const ParamFile pf = ParamFile::load(path("several_robots.ini"), "scout");
  ASSERT_TRUE(pf.has("vasco_border"));
  EXPECT_TRUE(pf.find("vasco_border")->expert);
  EXPECT_EQ(pf.get_int("vasco_border"), 30);
  EXPECT_FALSE(pf.find("vasco_resolution")->expert);
  EXPECT_FALSE(pf.find("robot_frontlaser_offset")->expert);
}

TEST(IniExpert, ExpertIsCaseInsensitiveAndNotARobot) {
  const ParamFile pf = ParamFile::parse("[EXPERT]\nvasco_a 1\n[*]\nvasco_b 2\n", "t.ini");
  EXPECT_TRUE(pf.robots().empty());
  EXPECT_TRUE(pf.find("vasco_a")->expert);
  EXPECT_FALSE(pf.find("vasco_b")->expert);
  // The flag belongs to the definition that wins.
  const ParamFile again = ParamFile::parse("[expert]\nvasco_a 1\n[*]\nvasco_a 2\n", "t.ini");
  EXPECT_FALSE(again.find("vasco_a")->expert);
}

TEST(IniExpert, OtherExpertSectionsAreNeitherRobotsNorApplied) {
  const ParamFile pf =
      ParamFile::parse("[*]\nvasco_a 1\n[expert_only]\nvasco_a 2\n", "t.ini");
  EXPECT_TRUE(pf.robots().empty());
  EXPECT_EQ(value_of(pf, "vasco_a"), "1");
  EXPECT_EQ(warning_texts(pf),
            std::vector<std::string>{
                "t.ini:3: section [expert_only] is neither [expert] nor a robot; its lines are "
                "ignored"});
}

// A device that never ends (or a huge file) is refused at 16 MiB instead of
// being read into memory without bound.
TEST(IniLimits, AnEndlessDeviceIsRefusedBeforeAnyRead) {
  // Not a regular file: refused by what it is (the 16 MiB cap is for files).
  try {
    carmen::ParamFile::load("/dev/zero");
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), "/dev/zero");
    EXPECT_NE(std::string(e.what()).find("is a character device, not a regular file"), std::string::npos) << e.what();
  }
}

TEST(IniLimits, AFileOverTheSizeCapIsRefused) {
  TempDir dir;
  const std::string big = dir.file("big.ini");
  { std::ofstream(big) << "[*]\n"; }
  std::filesystem::resize_file(big, (16u << 20) + 1);  // sparse: no 16 MiB written
  try {
    carmen::ParamFile::load(big);
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), big);
    EXPECT_NE(std::string(e.what()).find("larger than 16 MiB"), std::string::npos) << e.what();
  }
}

// 10^5 robot sections: linear, and the message lists a few of them.
TEST(IniLimits, ManyRobotSectionsAreCheapAndTheMessageBounded) {
  std::string text;
  for (int i = 0; i < 100000; ++i) text += "[robot" + std::to_string(i) + "]\nvasco_p_occ 0.6\n";
  const carmen::ParamFile pf = carmen::ParamFile::parse(text, "many.ini", "robot99999");
  EXPECT_EQ(pf.robots().size(), 100000u);
  EXPECT_EQ(pf.selected_robot(), "robot99999");
  try {
    carmen::ParamFile::parse(text, "many.ini");
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_LT(std::string(e.what()).size(), 400u) << e.what();
    EXPECT_NE(std::string(e.what()).find("and 99990 more"), std::string::npos) << e.what();
  }
}

}  // namespace
