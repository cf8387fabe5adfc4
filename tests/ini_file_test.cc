// carmen.ini reading: every syntax, section and priority rule, one test each.
// Expected values follow from the rules and the test files, worked out by hand.
#include "carmen_compat/ini_file.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include <clocale>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "temp_dir.h"

namespace {

using carmen::FileError;
using carmen::ParamFile;
using carmen::ParamValue;

const std::string kDir = std::string(VASCO_TEST_DATA_DIR) + "/ini/";

std::string path(const std::string &name) { return kDir + name; }

// what() of the FileError that `f` throws ("" and a failure when none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const FileError &e) {
    return e.what();
  }
  ADD_FAILURE() << "no FileError was thrown";
  return "";
}

::testing::AssertionResult contains(const std::string &text, const std::string &part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// The value of `name`, or a marker when it is not defined.
std::string value_of(const ParamFile &pf, const std::string &name) {
  const auto pv = pf.find(name);
  return pv ? pv->value : "<undefined>";
}

long line_of(const ParamFile &pf, const std::string &name) {
  const auto pv = pf.find(name);
  return pv ? pv->line : -1;
}

std::vector<std::string> warning_texts(const ParamFile &pf) {
  std::vector<std::string> out;
  for (const auto &w : pf.warnings()) out.push_back(w.str());
  return out;
}

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

// ---------------------------------------------------------------------------
// Sources and priorities

TEST(IniSources, IniBeatsLogParamLines) {
  ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ 0.9\n", "c.ini");
  pf.add_fallback("vasco_p_occ", "0.7", "run.log", 12);
  pf.add_fallback("robot_length", "0.8", "run.log", 13);
  EXPECT_EQ(pf.find("vasco_p_occ")->where(), "c.ini:2");
  EXPECT_DOUBLE_EQ(pf.get_double("vasco_p_occ"), 0.9);
  // The log fills what the ini does not define.
  EXPECT_EQ(pf.find("robot_length")->where(), "run.log:13");
  EXPECT_DOUBLE_EQ(pf.get_double("robot_length"), 0.8);
}

TEST(IniSources, IniDefinitionWithoutValueStillBeatsTheLog) {
  ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ\n", "c.ini");
  pf.add_fallback("vasco_p_occ", "0.7", "run.log", 12);
  EXPECT_EQ(pf.find("vasco_p_occ")->where(), "c.ini:2");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_occ"); }), "c.ini:2: vasco_p_occ has no value");
}

TEST(IniSources, LaterFallbackReplacesEarlierAndMatchesCaseInsensitively) {
  ParamFile pf;
  pf.add_fallback("robot_length", "0.8", "run.log", 3);
  pf.add_fallback("ROBOT_LENGTH", " 0.9 ", "run.log", 4);
  EXPECT_EQ(value_of(pf, "robot_length"), "0.9");
  EXPECT_EQ(line_of(pf, "robot_length"), 4);
}

TEST(IniSources, OverrideBeatsIniAndLog) {
  ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ 0.9\n", "c.ini");
  pf.add_fallback("vasco_p_occ", "0.7", "run.log", 12);
  pf.add_fallback("robot_length", "0.8", "run.log", 13);
  pf.set_override("VASCO_P_OCC", "0.6");
  pf.set_override("robot_length", "0.3");
  const auto pv = pf.find("vasco_p_occ");
  ASSERT_TRUE(pv.has_value());
  EXPECT_EQ(pv->file, "command line");
  EXPECT_EQ(pv->line, 0);
  EXPECT_EQ(pv->where(), "command line");
  EXPECT_DOUBLE_EQ(pf.get_double("vasco_p_occ"), 0.6);
  EXPECT_DOUBLE_EQ(pf.get_double("robot_length"), 0.3);
  // An override may also define a name nobody else does; a later one wins.
  pf.set_override("vasco_border", "5");
  pf.set_override("vasco_border", "6");
  EXPECT_EQ(pf.get_int("vasco_border"), 6);
}

TEST(IniSources, OverrideNameMustBeModuleVariable) {
  ParamFile pf;
  EXPECT_EQ(error_of([&] { pf.set_override("border", "5"); }),
            "command line: 'border' is not a module_variable parameter name");
}

TEST(IniSources, FallbackNameMustBeModuleVariable) {
  ParamFile pf;
  pf.add_fallback("border", "5", "run.log", 7);
  EXPECT_FALSE(pf.has("border"));
  EXPECT_EQ(warning_texts(pf),
            std::vector<std::string>{"run.log:7: 'border' is not module_variable; ignored"});
}

TEST(IniSources, AllListsEffectiveDefinitionsByName) {
  ParamFile pf = ParamFile::parse("[*]\nvasco_b 1\nVasco_A 2\n", "c.ini");
  pf.add_fallback("vasco_a", "9", "run.log", 1);
  pf.add_fallback("robot_x", "3", "run.log", 2);
  pf.set_override("vasco_b", "4");
  const std::vector<ParamValue> all = pf.all();
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].name, "robot_x");
  EXPECT_EQ(all[0].where(), "run.log:2");
  EXPECT_EQ(all[1].name, "Vasco_A");
  EXPECT_EQ(all[1].value, "2");
  EXPECT_EQ(all[2].name, "vasco_b");
  EXPECT_EQ(all[2].value, "4");
  EXPECT_EQ(all[2].where(), "command line");
}

// ---------------------------------------------------------------------------
// Typed values

TEST(IniDouble, ParsesWhatStrtodAccepts) {
  const ParamFile pf = ParamFile::parse(
      "[*]\nv_a 0.025\nv_b -1.5e-3\nv_c +2\nv_d 0x1p-2\nv_e .5\nv_f 7.\nv_g 1E2\n", "t.ini");
  EXPECT_EQ(pf.get_double("v_a"), 0.025);
  EXPECT_EQ(pf.get_double("v_b"), -0.0015);
  EXPECT_EQ(pf.get_double("v_c"), 2.0);
  EXPECT_EQ(pf.get_double("v_d"), 0.25);
  EXPECT_EQ(pf.get_double("v_e"), 0.5);
  EXPECT_EQ(pf.get_double("v_f"), 7.0);
  EXPECT_EQ(pf.get_double("v_g"), 100.0);
}

TEST(IniDouble, ErrorsNameFileLineAndKey) {
  const ParamFile pf = ParamFile::parse(
      "[*]\nvasco_p_occ abc\nvasco_p_emp 0.45m\nvasco_p_prior 0.5 0.6\nvasco_wall_size\n",
      "c.ini");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_occ"); }),
            "c.ini:2: vasco_p_occ: 'abc' is not a number");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_emp"); }),
            "c.ini:3: vasco_p_emp: '0.45m' is not a number");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_prior"); }),
            "c.ini:4: vasco_p_prior: '0.5 0.6' is not a number");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_wall_size"); }),
            "c.ini:5: vasco_wall_size has no value");
  try {
    pf.get_double("vasco_p_occ");
  } catch (const FileError &e) {
    EXPECT_EQ(e.file(), "c.ini");
    EXPECT_EQ(e.line(), 2);
  }
}

TEST(IniDouble, NonFiniteValuesAreErrors) {
  const ParamFile pf =
      ParamFile::parse("[*]\nv_inf inf\nv_ninf -Infinity\nv_nan nan\nv_big 1e999\n", "t.ini");
  EXPECT_EQ(error_of([&] { pf.get_double("v_inf"); }), "t.ini:2: v_inf: 'inf' is not a finite number");
  EXPECT_EQ(error_of([&] { pf.get_double("v_ninf"); }),
            "t.ini:3: v_ninf: '-Infinity' is not a finite number");
  EXPECT_EQ(error_of([&] { pf.get_double("v_nan"); }), "t.ini:4: v_nan: 'nan' is not a finite number");
  EXPECT_EQ(error_of([&] { pf.get_double("v_big"); }),
            "t.ini:5: v_big: '1e999' is not a finite number");
}

TEST(IniDouble, FallbackOnlyWhenUndefined) {
  const ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ 0.9\nvasco_p_emp x\n", "c.ini");
  EXPECT_EQ(pf.get_double("vasco_p_occ", 0.55), 0.9);
  EXPECT_EQ(pf.get_double("vasco_range_max", 10.0), 10.0);
  // Defined but bad is an error, not the fallback.
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_emp", 0.45); }),
            "c.ini:3: vasco_p_emp: 'x' is not a number");
}

TEST(IniDouble, MissingNameIsAnErrorNamingTheFile) {
  const ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ 0.9\n", "c.ini");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_range_max"); }),
            "c.ini: vasco_range_max is not defined");
  const ParamFile scout = ParamFile::load(path("one_robot.ini"));
  EXPECT_EQ(error_of([&] { scout.get_string("vasco_border"); }),
            path("one_robot.ini") + ": vasco_border is not defined (robot Scout)");
  const ParamFile none;
  EXPECT_EQ(error_of([&] { none.get_int("vasco_border"); }), "parameters: vasco_border is not defined");
}

TEST(IniDouble, ErrorsFromOtherSourcesNameThem) {
  ParamFile pf;
  pf.add_fallback("vasco_p_occ", "high", "run.log", 40);
  pf.set_override("vasco_p_emp", "low");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_occ"); }),
            "run.log:40: vasco_p_occ: 'high' is not a number");
  EXPECT_EQ(error_of([&] { pf.get_double("vasco_p_emp"); }),
            "command line: vasco_p_emp: 'low' is not a number");
}

TEST(IniDouble, IndependentOfTheProcessLocale) {
  const char *previous = std::setlocale(LC_NUMERIC, nullptr);
  const std::string saved = previous ? previous : "C";
  const char *comma_locales[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8",
                                 "de_DE", "fr_FR"};
  bool switched = false;
  for (const char *name : comma_locales)
    if (std::setlocale(LC_NUMERIC, name) != nullptr) {
      switched = true;
      break;
    }
  // CI generates de_DE.UTF-8 (localedef) and sets VASCO_REQUIRE_LOCALE_TESTS:
  // there the test must run; elsewhere it skips.
  if (!switched && std::getenv("VASCO_REQUIRE_LOCALE_TESTS") != nullptr)
    FAIL() << "no locale with a decimal comma is installed (generate de_DE.UTF-8 with localedef)";
  if (!switched) GTEST_SKIP() << "no locale with a decimal comma is installed";
  const ParamFile pf = ParamFile::parse("[*]\nv_a 0.025\nv_b 0,5\n", "t.ini");
  const double a = pf.get_double("v_a");
  const std::string b_error = error_of([&] { pf.get_double("v_b"); });
  std::setlocale(LC_NUMERIC, saved.c_str());
  EXPECT_EQ(a, 0.025);
  EXPECT_EQ(b_error, "t.ini:3: v_b: '0,5' is not a number");
}

TEST(IniInt, StrtolBaseZero) {
  const ParamFile pf = ParamFile::parse(
      "[*]\nv_dec 10\nv_hex 0x1F\nv_hex2 0X1f\nv_oct 010\nv_noct -010\nv_plus +7\nv_zero 0\n"
      "v_neg -42\n",
      "t.ini");
  EXPECT_EQ(pf.get_int("v_dec"), 10);
  EXPECT_EQ(pf.get_int("v_hex"), 31);
  EXPECT_EQ(pf.get_int("v_hex2"), 31);
  EXPECT_EQ(pf.get_int("v_oct"), 8);
  EXPECT_EQ(pf.get_int("v_noct"), -8);
  EXPECT_EQ(pf.get_int("v_plus"), 7);
  EXPECT_EQ(pf.get_int("v_zero"), 0);
  EXPECT_EQ(pf.get_int("v_neg"), -42);
}

TEST(IniInt, TrailingJunkAndOverflowAreErrors) {
  const ParamFile pf = ParamFile::parse(
      "[*]\nv_a 1.5\nv_b 12abc\nv_c 0x\nv_d 08\nv_e 99999999999999999999\nv_f four\nv_g\n",
      "t.ini");
  EXPECT_EQ(error_of([&] { pf.get_int("v_a"); }), "t.ini:2: v_a: '1.5' is not an integer");
  EXPECT_EQ(error_of([&] { pf.get_int("v_b"); }), "t.ini:3: v_b: '12abc' is not an integer");
  EXPECT_EQ(error_of([&] { pf.get_int("v_c"); }), "t.ini:4: v_c: '0x' is not an integer");
  EXPECT_EQ(error_of([&] { pf.get_int("v_d"); }),
            "t.ini:5: v_d: '08' is not an integer (a leading 0 means octal)");
  EXPECT_EQ(error_of([&] { pf.get_int("v_e"); }),
            "t.ini:6: v_e: '99999999999999999999' is out of range");
  EXPECT_EQ(error_of([&] { pf.get_int("v_f"); }), "t.ini:7: v_f: 'four' is not an integer");
  EXPECT_EQ(error_of([&] { pf.get_int("v_g"); }), "t.ini:8: v_g has no value");
}

TEST(IniInt, FallbackOnlyWhenUndefined) {
  const ParamFile pf = ParamFile::parse("[*]\nvasco_border 30\nvasco_downsample 4x\n", "t.ini");
  EXPECT_EQ(pf.get_int("vasco_border", 20), 30);
  EXPECT_EQ(pf.get_int("vasco_first_scan", 0), 0);
  EXPECT_EQ(error_of([&] { pf.get_int("vasco_downsample", 4); }),
            "t.ini:3: vasco_downsample: '4x' is not an integer");
}

TEST(IniOnOff, CaseInsensitivePrefixes) {
  const ParamFile pf = ParamFile::parse(
      "[*]\nv_a on\nv_b ON\nv_c On\nv_d online\nv_e off\nv_f OFF\nv_g Offline\n", "t.ini");
  EXPECT_TRUE(pf.get_onoff("v_a"));
  EXPECT_TRUE(pf.get_onoff("v_b"));
  EXPECT_TRUE(pf.get_onoff("v_c"));
  EXPECT_TRUE(pf.get_onoff("v_d"));
  EXPECT_FALSE(pf.get_onoff("v_e"));
  EXPECT_FALSE(pf.get_onoff("v_f"));
  EXPECT_FALSE(pf.get_onoff("v_g"));
}

TEST(IniOnOff, OtherWordsAreErrors) {
  const ParamFile pf =
      ParamFile::parse("[*]\nv_a yes\nv_b 1\nv_c o\nv_d of\nv_e true\nv_f\n", "t.ini");
  EXPECT_EQ(error_of([&] { pf.get_onoff("v_a"); }), "t.ini:2: v_a: 'yes' is not on or off");
  EXPECT_EQ(error_of([&] { pf.get_onoff("v_b"); }), "t.ini:3: v_b: '1' is not on or off");
  EXPECT_EQ(error_of([&] { pf.get_onoff("v_c"); }), "t.ini:4: v_c: 'o' is not on or off");
  EXPECT_EQ(error_of([&] { pf.get_onoff("v_d"); }), "t.ini:5: v_d: 'of' is not on or off");
  EXPECT_EQ(error_of([&] { pf.get_onoff("v_e"); }), "t.ini:6: v_e: 'true' is not on or off");
  EXPECT_EQ(error_of([&] { pf.get_onoff("v_f"); }), "t.ini:7: v_f has no value");
}

TEST(IniOnOff, FallbackOnlyWhenUndefined) {
  const ParamFile pf = ParamFile::parse("[*]\nrobot_interpolate_odometry on\n", "t.ini");
  EXPECT_TRUE(pf.get_onoff("robot_interpolate_odometry", false));
  EXPECT_FALSE(pf.get_onoff("robot_use_sonar", false));
  EXPECT_TRUE(pf.get_onoff("robot_use_laser", true));
}

TEST(IniString, ValueAsWritten) {
  const ParamFile pf = ParamFile::parse("[*]\nlaser_type LMS 291\n", "t.ini");
  EXPECT_EQ(pf.get_string("laser_type"), "LMS 291");
  EXPECT_EQ(pf.get_string("laser_dev", "none"), "none");
  EXPECT_EQ(pf.get_string("LASER_TYPE", "none"), "LMS 291");
}

// ---------------------------------------------------------------------------
// Unknown names (typos)

const std::vector<std::string> kVascoKeys = {
    "vasco_resolution", "vasco_p_prior",    "vasco_p_occ",     "vasco_p_emp",
    "vasco_range_sure", "vasco_range_max",  "vasco_wall_size", "vasco_downsample",
    "vasco_border",     "vasco_first_scan", "vasco_num_scans"};

TEST(IniUnknown, ReportsNamesOfTheModuleNotKnown) {
  const ParamFile pf = ParamFile::load(path("vasco_typo.ini"));
  const std::vector<ParamValue> unknown = pf.unknown_in_module("vasco", kVascoKeys);
  ASSERT_EQ(unknown.size(), 2u);
  EXPECT_EQ(unknown[0].name, "vasco_p_ocupied");
  EXPECT_EQ(unknown[0].where(), path("vasco_typo.ini") + ":4");
  EXPECT_EQ(unknown[1].name, "vasco_max_usable_laser_range");
  EXPECT_EQ(unknown[1].where(), path("vasco_typo.ini") + ":6");
  // robot_length is another module's business.
  EXPECT_TRUE(pf.unknown_in_module("robot", {"robot_length"}).empty());
}

TEST(IniUnknown, KnownMayBeVariablesAndAnyCase) {
  const ParamFile pf = ParamFile::load(path("vasco_typo.ini"));
  const std::vector<ParamValue> unknown = pf.unknown_in_module(
      "VASCO", {"RESOLUTION", "p_occ", "range_max", "Vasco_Max_Usable_Laser_Range"});
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0].name, "vasco_p_ocupied");
}

TEST(IniUnknown, OverridesCountFallbacksDoNot) {
  ParamFile pf = ParamFile::parse("[*]\nvasco_p_occ 0.9\nvasco_bordr 3\n", "c.ini");
  pf.add_fallback("vasco_local_map_max_range", "20", "run.log", 5);
  pf.set_override("vasco_resoltion", "0.1");
  pf.set_override("vasco_bordr", "4");
  const std::vector<ParamValue> unknown = pf.unknown_in_module("vasco", kVascoKeys);
  ASSERT_EQ(unknown.size(), 2u);
  // The ini's typo first, with its effective (overridden) definition.
  EXPECT_EQ(unknown[0].name, "vasco_bordr");
  EXPECT_EQ(unknown[0].where(), "command line");
  EXPECT_EQ(unknown[1].name, "vasco_resoltion");
  EXPECT_EQ(unknown[1].where(), "command line");
}

// ---------------------------------------------------------------------------
// The shipped defaults

TEST(IniVascoDefault, HoldsTheVascoDefaults) {
  const ParamFile pf = ParamFile::load(path("vasco_default.ini"));
  EXPECT_TRUE(pf.warnings().empty());
  EXPECT_TRUE(pf.robots().empty());
  EXPECT_EQ(pf.get_double("vasco_resolution"), 0.025);
  EXPECT_EQ(pf.get_double("vasco_p_prior"), 0.5);
  EXPECT_EQ(pf.get_double("vasco_p_occ"), 0.55);
  EXPECT_EQ(pf.get_double("vasco_p_emp"), 0.45);
  EXPECT_EQ(pf.get_double("vasco_range_sure"), 5.0);
  EXPECT_EQ(pf.get_double("vasco_range_max"), 10.0);
  EXPECT_EQ(pf.get_double("vasco_wall_size"), 0.2);
  EXPECT_EQ(pf.get_int("vasco_downsample"), 4);
  EXPECT_EQ(pf.get_int("vasco_border"), 20);
  EXPECT_EQ(pf.all().size(), 9u);
  EXPECT_TRUE(pf.unknown_in_module("vasco", kVascoKeys).empty());
}

}  // namespace

namespace {

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
