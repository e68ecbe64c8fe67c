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

/// Whether a group of `ones` type-1 and `twos` type-2 robots includes a feasible team for a task of type `task`.
pub fn includes_feasible(task: Kind, ones: usize, twos: usize) -> bool {
    let teams: [(&[Kind], usize, usize); 5] = [
        (&[Kind::One], 1, 0),
        (&[Kind::Two], 0, 1),
        (&[Kind::One, Kind::One], 2, 0),
        (&[Kind::One, Kind::Two], 1, 1),
        (&[Kind::Two, Kind::Two], 0, 2),
    ];
    teams.iter().any(|&(team, need_ones, need_twos)| {
        ones >= need_ones && twos >= need_twos && feasible(task, team)
    })
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

    #[test]
    fn a_group_includes_a_team_when_some_part_of_it_is_one() {
        assert!(includes_feasible(One, 1, 0) && includes_feasible(One, 0, 1));
        assert!(
            includes_feasible(Two, 0, 1)
                && includes_feasible(Two, 2, 0)
                && includes_feasible(Two, 3, 2)
        );
        assert!(!includes_feasible(Two, 1, 0) && !includes_feasible(One, 0, 0));
    }
}
