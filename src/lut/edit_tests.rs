//! Tests of `lut::edit`: regions, applying and reverting edits, the bounded undo history.

use super::*;

fn around(y: u8, u: u8, v: u8, s: u8) -> Region {
    Region::AroundSample {
        sample: Yuv::new(y, u, v),
        sensitivity: Sensitivity::uniform(s),
    }
}

#[test]
fn sensitivity_zero_selects_one_cell_and_one_widens_by_one() {
    let lut = LookupTable::new(7).unwrap();
    let Selection::Box(b) = around(100, 100, 100, 0).select(&lut) else {
        panic!("box expected")
    };
    assert_eq!(b.len(), 1);
    assert_eq!(b.min, [50, 50, 50]);
    let Selection::Box(b) = around(100, 100, 100, 1).select(&lut) else {
        panic!("box expected")
    };
    assert_eq!((b.min, b.max, b.len()), ([49; 3], [51; 3], 27));
}

#[test]
fn selection_is_clamped_at_the_table_edges() {
    let lut = LookupTable::new(6).unwrap();
    let Selection::Box(b) = around(0, 255, 3, 2).select(&lut) else {
        panic!("box expected")
    };
    assert_eq!(b.min, [0, 61, 0]);
    assert_eq!(b.max, [2, 63, 2]);
    assert_eq!(b.len(), 3 * 3 * 3);
}

#[test]
fn preview_marks_matching_pixels_without_writing() {
    let lut = LookupTable::new(7).unwrap();
    let frame = Frame::uyvy_from_fn(4, 2, |x, _| {
        if x < 2 {
            Yuv::new(120, 80, 190)
        } else {
            Yuv::new(60, 128, 128)
        }
    })
    .unwrap();
    let sel = around(121, 81, 191, 0).select(&lut);
    let mask = sel.preview_mask(&lut, &frame);
    assert_eq!(mask, [true, true, false, false, true, true, false, false]);
    assert_eq!(
        lut.class_counts()[0],
        lut.cells().len(),
        "preview writes nothing"
    );
}

#[test]
fn commit_undo_redo_restore_exact_tables() {
    let mut lut = LookupTable::new(6).unwrap();
    let mut history = EditHistory::default();
    let empty = lut.clone();
    let changed = history.commit(
        &mut lut,
        EditRecord::now(ColourClass::Orange, around(120, 80, 190, 1)),
    );
    assert_eq!(changed, 27);
    let after_first = lut.clone();
    // An overlapping edit changes only the cells that differ.
    let changed = history.commit(
        &mut lut,
        EditRecord::now(ColourClass::Green, around(124, 80, 190, 1)),
    );
    assert_eq!(changed, 27);
    // Y cells 29..=31 then 30..=32: two of the three orange layers were overwritten.
    assert_eq!(lut.class_counts()[1], 9);
    assert_eq!(lut.class_counts()[5], 27);
    let after_second = lut.clone();

    assert_eq!(
        history.undo(&mut lut).map(|r| r.class),
        Some(ColourClass::Green)
    );
    assert_eq!(lut, after_first);
    assert_eq!(
        history.undo(&mut lut).map(|r| r.class),
        Some(ColourClass::Orange)
    );
    assert_eq!(lut, empty);
    assert!(history.undo(&mut lut).is_none());
    history.redo(&mut lut);
    history.redo(&mut lut);
    assert_eq!(lut, after_second);
    assert!(history.redo(&mut lut).is_none());
}

#[test]
fn new_commit_clears_redo_and_history_is_bounded_by_bytes() {
    let mut lut = LookupTable::new(6).unwrap();
    let one = |i: u8| EditRecord::now(ColourClass::Pink, around(i * 40, 10, 10, 0));
    // Room for three one-cell steps.
    let step = lut.clone().apply(one(0)).held_bytes();
    let mut history = EditHistory::new(3 * step);
    for i in 0..5u8 {
        history.commit(&mut lut, one(i));
    }
    assert_eq!((history.undo_len(), history.dropped()), (3, 2));
    assert!(history.held_bytes() <= 3 * step);
    history.undo(&mut lut);
    assert_eq!(history.redo_len(), 1);
    history.commit(
        &mut lut,
        EditRecord::now(ColourClass::White, around(250, 128, 128, 0)),
    );
    assert_eq!(history.redo_len(), 0);
    assert_eq!(
        history.held_bytes(),
        3 * step,
        "the redo step's bytes are freed"
    );
    // A step larger than the whole limit is still kept, alone: it can be undone.
    let whole = EditRecord::now(ColourClass::Green, around(128, 128, 128, 63));
    history.commit(&mut lut, whole);
    assert_eq!((history.undo_len(), history.dropped()), (1, 5));
    history.undo(&mut lut);
    assert_eq!(lut.class_counts()[5], 0);
}

#[test]
fn picked_cells_apply_like_their_selection() {
    let indices = vec![900, 5, 9, 5, 1 << 30];
    let region = Region::Cells {
        indices: indices.clone(),
    };
    let mut direct = LookupTable::new(6).unwrap();
    let applied = direct.apply(EditRecord::now(ColourClass::Yellow, region.clone()));
    let expected: Vec<usize> = region.select(&direct).indices(&direct).collect();
    assert_eq!(expected, [5, 9, 900]);
    let PreviousCodes::Cells { indices, .. } = &applied.previous else {
        panic!("picked cells keep a list");
    };
    let changed: Vec<usize> = indices.iter().map(|&i| i as usize).collect();
    assert_eq!(changed, expected, "sorted, once each, inside the table");
}

#[test]
fn explicit_cells_region_and_records_serialise() {
    let mut lut = LookupTable::new(6).unwrap();
    let record = EditRecord {
        class: ColourClass::Yellow,
        region: Region::Cells {
            indices: vec![5, 9, usize::MAX],
        },
        time_unix_ms: 42,
        sampled_at: Some(SampleAt {
            frame: 3,
            x: 10,
            y: 20,
        }),
    };
    let json = serde_json::to_string(&record).unwrap();
    let back: EditRecord = serde_json::from_str(&json).unwrap();
    assert_eq!(back, record);
    let applied = lut.apply(back);
    assert_eq!(applied.changed_cells(), 2, "out-of-range index ignored");
    assert_eq!(lut.get(9), Some(3));
}

/// Boxes whose rows join up (every V; every U and V; the whole table) are written as
/// longer runs: the cells set and the codes kept must be those of a cell-by-cell walk.
#[test]
fn boxes_of_every_shape_set_and_revert_exactly_their_cells() {
    let side = 64; // a 6-bit table
    let boxes = [
        ([0, 0, 0], [63, 63, 63]), // the whole table
        ([3, 0, 0], [9, 63, 63]),  // every U and V of some Y
        ([3, 2, 0], [9, 11, 63]),  // every V
        ([3, 2, 5], [9, 11, 7]),   // a small box
        ([63, 63, 63], [63, 63, 63]),
    ];
    let mut lut = LookupTable::new(6).unwrap();
    // A table of varied codes, so the kept old codes are checked cell by cell.
    let varied = EditRecord::now(ColourClass::Green, around(0, 0, 0, 20));
    lut.apply(varied);
    let mut history = EditHistory::default();
    for (n, (min, max)) in boxes.into_iter().enumerate() {
        let before = lut.clone();
        let cells = CellBox { min, max };
        let code = ColourClass::Orange.code();
        let (previous, changed) = lut.apply_to_box(cells, code, Vec::new());
        let mut expected = before.clone();
        let mut expected_changed = 0;
        for i in 0..side * side * side {
            let c = expected.cell_of_index(i);
            if (0..3).all(|k| (min[k]..=max[k]).contains(&c[k])) {
                expected_changed += usize::from(expected.cells()[i] != code);
                expected.cells[i] = code;
            }
        }
        assert_eq!(lut, expected, "box {n}");
        assert_eq!(changed, expected_changed, "box {n}");
        lut.revert(&AppliedEdit {
            record: EditRecord::now(ColourClass::Orange, around(0, 0, 0, 0)),
            previous,
            changed,
        });
        assert_eq!(lut, before, "box {n} reverted");
        // Through the history, whose dropped steps' buffers are reused.
        history.commit(
            &mut lut,
            EditRecord::now(ColourClass::Orange, around(128, 128, 128, 15)),
        );
        history.undo(&mut lut);
        assert_eq!(lut, before, "box {n} undone");
    }
}

#[test]
fn a_bounded_history_reuses_dropped_buffers_and_still_undoes_exactly() {
    let mut lut = LookupTable::new(6).unwrap();
    // Room for two whole-table steps (262,144 cells each) and their records.
    let mut history = EditHistory::new(2 * (1 << 18) + 1024);
    let classes = [ColourClass::Orange, ColourClass::Green, ColourClass::White];
    let mut tables = vec![lut.clone()];
    for i in 0..6 {
        let whole = EditRecord::now(classes[i % 3], around(128, 128, 128, 63));
        history.commit(&mut lut, whole);
        tables.push(lut.clone());
    }
    assert_eq!(history.dropped(), 4);
    assert_eq!(history.undo_len(), 2);
    history.undo(&mut lut);
    assert_eq!(lut, tables[5]);
    history.undo(&mut lut);
    assert_eq!(lut, tables[4]);
    assert!(
        history.undo(&mut lut).is_none(),
        "dropped steps cannot be undone"
    );
    history.redo(&mut lut);
    history.redo(&mut lut);
    assert_eq!(lut, tables[6]);
}
