//! The extremes matrix: every extreme class × every kernel × every path keeps the contract.

use bvkit_support::matrix;

#[test]
fn every_cell_of_the_extremes_matrix_keeps_the_contract() {
    let cells = matrix::compute();
    let mut failures = Vec::new();
    for (ti, table) in cells.iter().enumerate() {
        for row in table {
            for cell in row {
                assert_eq!(
                    cell.cases as u64 % matrix::CASES,
                    0,
                    "every cell ran its cases"
                );
                failures.extend(
                    cell.failures
                        .iter()
                        .map(|f| format!("{}: {f}", matrix::TABLES[ti])),
                );
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures, first: {}",
        failures.len(),
        failures[0]
    );
}

#[test]
fn mat4_cases_give_their_documented_outcome() {
    for (case, expected, observed, ok) in matrix::mat4_cases() {
        assert!(ok, "{case}: expected {expected}, got {observed}");
    }
}
