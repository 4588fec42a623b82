"""Plain-Python reference formulas of the hardware contract, one pixel / one loop at a time.

Written straight from the tables of docs/contract.md with Python ints, independently of the
vectorised numpy model, so that tests can compare the two.
"""


def scalar_match(pixel, color_sel, diff_min=6, similar_max=2, white_min=12):
    """Does one packed RGB444 pixel match colour ``color_sel`` (the contract's table)?"""
    r, g, b = (pixel >> 8) & 0xF, (pixel >> 4) & 0xF, pixel & 0xF
    if color_sel == 0b000:
        return True
    if color_sel == 0b100:
        return r - max(g, b) >= diff_min
    if color_sel == 0b010:
        return g - max(r, b) >= diff_min
    if color_sel == 0b001:
        return b - max(r, g) >= diff_min
    if color_sel == 0b110:
        return abs(r - g) <= similar_max and min(r, g) - b >= diff_min
    if color_sel == 0b101:
        return abs(r - b) <= similar_max and min(r, b) - g >= diff_min
    if color_sel == 0b011:
        return abs(g - b) <= similar_max and min(g, b) - r >= diff_min
    if color_sel == 0b111:
        return max(r, g, b) - min(r, g, b) <= similar_max and min(r, g, b) >= white_min
    raise ValueError(color_sel)


def loop_track(match_rows, params):
    """Count N, the 8 bins and SX with a loop over every pixel of the window.

    ``match_rows`` is a list of rows of bools. Returns ``(n, bins, sum_x)``.
    """
    bins = [0] * 8
    n = sum_x = 0
    x0, x1 = params.margin_x, params.width - params.margin_x
    y0, y1 = params.margin_y, params.height - params.margin_y
    bin_width = (x1 - x0) // 8
    for y in range(y0, y1):
        for x in range(x0, x1):
            if match_rows[y][x]:
                n += 1
                sum_x += x
                bins[(x - x0) // bin_width] += 1
    return n, bins, sum_x
