//! Which items reach each row of cells: [`RowLists`], a list per row in one array, for the
//! few big balls the grid keeps out of its cells.

use std::ops::{Range, RangeInclusive};

/// For each row, the items whose span of rows covers it, in item order: a counting sort of
/// `(row, item)`, rebuilt with its buffers kept.
#[derive(Debug, Default)]
pub struct RowLists {
    /// `start[row]..start[row + 1]` is the row's range in `items`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl RowLists {
    /// Lists item `k` in every row of `spans[k]`, for `rows` rows.
    pub fn rebuild<Spans>(&mut self, rows: usize, spans: Spans)
    where
        Spans: DoubleEndedIterator<Item = RangeInclusive<usize>> + ExactSizeIterator + Clone,
    {
        self.start.clear();
        self.start.resize(rows + 1, 0);
        for span in spans.clone() {
            for row in span {
                self.start[row] += 1;
            }
        }
        // Inclusive prefix sums, then a reverse scatter counting each row's end down to its
        // start: the items of a row stay in order (as in the grid's own sort).
        let mut running = 0;
        for count in &mut self.start[..rows] {
            running += *count;
            *count = running;
        }
        self.start[rows] = running;
        self.items.resize(running as usize, 0);
        for (item, span) in spans.enumerate().rev() {
            for row in span {
                let slot = &mut self.start[row];
                *slot -= 1;
                self.items[*slot as usize] = item as u32;
            }
        }
    }

    /// The items listed in `row`, in item order.
    pub fn in_row(&self, row: usize) -> &[u32] {
        let range: Range<usize> = self.start[row] as usize..self.start[row + 1] as usize;
        &self.items[range]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_row_lists_the_items_that_span_it_in_order() {
        let mut lists = RowLists::default();
        let spans = [1..=3, 0..=0, 2..=4, 4..=4];
        lists.rebuild(5, spans.iter().cloned());
        assert_eq!(lists.in_row(0), [1]);
        assert_eq!(lists.in_row(1), [0]);
        assert_eq!(lists.in_row(2), [0, 2]);
        assert_eq!(lists.in_row(3), [0, 2]);
        assert_eq!(lists.in_row(4), [2, 3]);
    }
}
