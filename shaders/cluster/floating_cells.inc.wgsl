// Finding a cell of the floating cells' hash grid; prepended (after floating.wgsl) to the stages
// that bind FloatParams and cell_key (fc_decide, fc_claim), which bind cell_head too.

const NO_CELL: u32 = 0xffffffffu;

// The cell of Morton key `key` by binary search over the sorted cell keys (cell_head[n] of them,
// each once: the hash grid has no SINGLETON keys), or NO_CELL.
fn find_cell(key: u32) -> u32 {
    let cells = cell_head[cluster.vertex_count];
    var lo = 0u;
    var hi = cells;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (cell_key[mid] < key) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    if (lo < cells && cell_key[lo] == key) {
        return lo;
    }
    return NO_CELL;
}
