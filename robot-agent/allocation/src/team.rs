//! Which teams can do a task (A.5.1): a type-1 task needs one robot of either type; a type-2 task needs one
//! type-2 robot or two type-1 robots; no task takes more than two.

use crate::model::Kind;

/// Whether robots of the types `team` make a feasible team for a task of type `task`.
pub fn feasible(task: Kind, team: &[Kind]) -> bool {
    matches!(
        (task, team),
        (Kind::One, [_]) | (Kind::Two, [Kind::Two]) | (Kind::Two, [Kind::One, Kind::One])
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use Kind::{One, Two};

    #[test]
    fn the_team_rules() {
        assert!(feasible(One, &[One]) && feasible(One, &[Two]));
        assert!(!feasible(One, &[]) && !feasible(One, &[One, One]));
        assert!(feasible(Two, &[Two]) && feasible(Two, &[One, One]));
        assert!(
            !feasible(Two, &[One]) && !feasible(Two, &[One, Two]) && !feasible(Two, &[Two, Two])
        );
        assert!(!feasible(Two, &[One, One, One]));
    }
}
