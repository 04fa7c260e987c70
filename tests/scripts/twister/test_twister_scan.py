"""Static scan of ztest sources for the expected cases."""

from twisterlib.scan import scan_sources, scan_text


def test_all_case_macros_are_found_with_test_prefix_stripped():
    text = """
    ZTEST_SUITE(core, NULL, setup, NULL, NULL, NULL);
    ZTEST(core, test_plain) {}
    ZTEST_F(core, test_with_fixture) {}
    ZTEST_USER(core, test_user) {}
    ZTEST_USER_F(core , test_user_fixture ) {}
    ZTEST(core, no_prefix) {}
    ZTEST(core, test_) {}
    """
    suites, cases = scan_text(text)
    assert suites == ["core"]
    assert cases == [
        ("core", "plain"),
        ("core", "with_fixture"),
        ("core", "user"),
        ("core", "user_fixture"),
        ("core", "no_prefix"),
        ("core", "test_"),
    ]


def test_comments_and_strings_do_not_count():
    text = """
    /* ZTEST(core, test_block_comment) {} */
    // ZTEST(core, test_line_comment) {}
    static const char *s = "ZTEST(core, test_in_string)";
    static const char *url = "http://x"; ZTEST(core, test_after_string) {}
    NOT_ZTEST(core, test_other_macro) {}
    """
    assert scan_text(text)[1] == [("core", "after_string")]


def test_sources_scanned_recursively_in_order_without_duplicates(tmp_path):
    src = tmp_path / "src"
    (src / "sub").mkdir(parents=True)
    (src / "a.c").write_text("ZTEST_SUITE(one, NULL, NULL, NULL, NULL, NULL);\nZTEST(one, test_x) {}\n")
    (src / "sub" / "b.cpp").write_text("ZTEST_SUITE(two, NULL, NULL, NULL, NULL, NULL);\nZTEST(two, test_y) {}\n")
    (src / "sub" / "c.h").write_text("ZTEST(two, test_in_header) {}\n")  # not a source file
    (src / "d.c").write_text("ZTEST(one, test_x) {}\n")
    suites, cases = scan_sources(tmp_path)
    assert suites == ["one", "two"]
    assert cases == ["one.x", "two.y"]


def test_no_src_folder_means_no_cases(tmp_path):
    assert scan_sources(tmp_path) == ([], [])
